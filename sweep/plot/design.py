"""The design chart of a 'sweep design' result (sweep/design.py): max_span against the one
axis the result has left, each point coloured by the criterion that binds it and labelled
with the values of the --over axes it binds at; a result with no axis left gets a single bar
with its value, criterion and binding values written on it."""

from __future__ import annotations

import textwrap
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..errors import UserError
from .labels import POINT_DIM, label, point_ticks
from .result import check_design_result
from .style import _coord, _is_log_spaced, _legend, _new_axes, _plain_ticks, _unit

CRITERION_STYLES = {
    "min_frequency": ("C0", "o", "first natural frequency (min_frequency)"),
    "max_amplitude": ("C3", "s", "response amplitude (max_amplitude)"),
    "max_deflection": ("C2", "v", "deflection over the span (max_deflection)"),
    "max_strain": ("C5", "P", "outer-fibre strain (max_strain)"),
    "max_rms": ("C6", "p", "mean RMS deflection (max_rms)"),
    "max_peak": ("C8", "h", "mean peak deflection (max_peak)"),
    "clearance": ("C9", "*", "clearance exceedance probability (clearance)"),
    "state": ("C1", "X", "run failed (state)"),
    "stability": ("C4", "D", "parametric instability (stability)"),
    "grid": ("0.5", "^", "none within the grid (grid: longest length)"),
}
"""limited_by -> (colour, marker, legend text)."""


def _scale(spans: np.ndarray) -> tuple[float, str]:
    finite = spans[np.isfinite(spans)]
    return (1e3, "mm") if finite.size == 0 or np.nanmax(np.abs(finite)) < 1.0 else (1.0, "m")


def _binding_text(da: xr.DataArray) -> str:
    """A binding_<axis> value of a result with no axis left, with its units as the figures
    show them (a displacement in mm, a level in g, a dB level in dB; none for a pure number):
    "0.08 kg/m", "-3 dB", "up"; '' where none binds (NaN, empty)."""
    at = da.values[()]
    if not isinstance(at, (float, np.number)):
        return "" if str(at) in ("", "nan") else str(at)
    if not np.isfinite(at):
        return ""
    factor, units = _unit(da)
    if units == "1" and " in dB" in str(da.attrs.get("comment", "")):   # quotes the axis's
        units = "dB"                                                     # long_name
    text = f"{float(at) * factor:g}"
    return f"{text} {units}" if units and units != "1" else text


MAX_POINT_LABELS = 12
"""Over more points than this the line chart writes a point's binding values only where they
change from the point before (a run of equal values labelled at its first point)."""


def _label_bindings(ax: Axes, ds: xr.Dataset, x: np.ndarray, y: np.ndarray,
                    floor: float) -> str:
    """Write above each point of the line chart the values its span binds at ('sweep design
    --over': the binding_<axis> variables, one a line, in their units as `_binding_text`
    gives them; a NaN span's at the marker on the floor). Returns the legend line naming the
    axes in the order the labels list them ('' where the result has none)."""
    names = [str(n) for n in ds.data_vars if str(n).startswith("binding_")]
    if not names:
        return ""
    texts = ["\n".join(_binding_text(ds[n][i]) or "-" for n in names) for i in range(len(x))]
    changes_only = len(x) > MAX_POINT_LABELS
    for i, text in enumerate(texts):
        if set(text.split("\n")) == {"-"} or (changes_only and i and text == texts[i - 1]):
            continue                                     # none binds (grid), or a repeat
        ax.annotate(text, (x[i], y[i] if np.isfinite(y[i]) else floor), xytext=(0, 7),
                    textcoords="offset points", ha="center", va="bottom", fontsize="small",
                    linespacing=1.0, zorder=3)
    ax.margins(x=0.1, y=0.08 + 0.06 * len(names))      # room for the top and end labels
    axes = " / ".join(n.removeprefix("binding_") for n in names)
    where = " where they change" if changes_only else ""
    return f"above each point{where}: the {axes} it binds at"


def plot_design(ds: xr.Dataset, *, ax: Axes | None = None, **kwargs: Any) -> Figure:
    """max_span (mm below 1 m, else m) of a design result: over one axis a line with markers
    coloured by `limited_by`, a legend naming the criteria and, for a span over other axes
    ('sweep design --over'), the values it binds at written above each point; over none a
    single bar with the value annotated. A NaN span (the shortest grid length fails) is marked at the bottom of
    the axes. Extra keyword arguments go to `Axes.plot` (or `Axes.bar`). Returns the Figure.
    Raises UserError (one line) for a result over more than one axis (select one value of the
    others first) or one the chart cannot show (`check_design_result`)."""
    check_design_result(ds)
    span, by = ds["max_span"], ds["limited_by"]
    if span.ndim > 1:
        raise UserError(f"plot_design: max_span lies over {', '.join(map(str, span.dims))}; "
                        "select one value of all but one axis (e.g. --select "
                        f"{span.dims[1]}={float(ds[span.dims[1]].values[0]):g})")
    ax = _new_axes() if ax is None else ax
    values = np.asarray(span.values, float).reshape(-1)
    factor, units = _scale(values)
    ylabel = f"largest span between clamps [{units}]"
    title = str(ds.attrs.get("title", "maximum span"))
    criteria = str(ds.attrs.get("criteria", ""))
    if span.ndim == 0:
        v, b = float(values[0]), str(by.values)
        colour, _, text = CRITERION_STYLES.get(b, ("0.3", "o", b))
        height = v * factor if np.isfinite(v) else 0.0
        ax.bar([0], [height], color=colour, width=0.5, **kwargs)
        note = (f"{v * factor:.4g} {units}\nlimited by {b}" if np.isfinite(v)
                else f"none: the shortest length\nfails {b}")
        for name in [n for n in ds.data_vars if str(n).startswith("binding_")]:
            shown = _binding_text(ds[name])  # 'sweep design --over': where the span binds
            if shown:
                note += f"\nat {str(name).removeprefix('binding_')} {shown}"
        ax.annotate(note, (0, height), xytext=(0, 4), textcoords="offset points",
                    ha="center", va="bottom")
        ax.set_xticks([0], ["max_span"])
        ax.set_xlim(-1, 1)
        ax.set_ylim(0, max(height, 1e-12) * (1.25 + 0.08 * max(note.count("\n") - 1, 0)))
    else:
        dim = span.dims[0]
        x = _coord(ds, dim)
        if dim != POINT_DIM:   # parameter sets are unrelated: no line from one to the next
            ax.plot(x, values * factor, color="0.6", lw=1.2, zorder=1, **kwargs)
        handles = []
        bys = np.asarray(by.values).astype(str)
        finite = values[np.isfinite(values)]
        floor = float(np.min(finite)) * factor * 0.95 if finite.size else 0.0
        for name in [n for n in CRITERION_STYLES if n in set(bys)] + \
                sorted(set(bys) - set(CRITERION_STYLES)):
            colour, marker, text = CRITERION_STYLES.get(name, ("0.3", "o", name))
            where = bys == name
            ok = where & np.isfinite(values)
            if ok.any():
                ax.scatter(x[ok], values[ok] * factor, color=colour, marker=marker, s=40,
                           zorder=2)
            if (where & ~np.isfinite(values)).any():
                ax.scatter(x[where & ~np.isfinite(values)],
                           np.full(int((where & ~np.isfinite(values)).sum()), floor),
                           color=colour, marker="v", s=40, zorder=2)
                text += "; v: shortest length fails"
            handles.append(Line2D([], [], color=colour, marker=marker, ls="", label=text))
        key = _label_bindings(ax, ds, x, values * factor, floor)
        if key:
            handles.append(Line2D([], [], ls="", label=key))
        ax.set_xlabel(label(ds[dim], units=_unit(ds[dim])[1]))
        if dim == POINT_DIM:
            point_ticks(ax, ds, "x")
        elif _is_log_spaced(x):
            ax.set_xscale("log")
        _legend(ax, handles, title="limited by")
    ax.set_ylabel(ylabel)
    criteria = "\n".join(textwrap.wrap(criteria, 90))
    ax.set_title(title if not criteria else f"{title}\n{criteria}", fontsize="small")
    refine = ds.attrs.get("refine_runs")
    if refine is not None:
        ax.text(0.99, 0.01, f"refined: {int(refine)} runs, tolerance "
                f"{float(ds.attrs.get('refine_tolerance', np.nan)):g} m",
                transform=ax.transAxes, ha="right", va="bottom", fontsize="x-small")
    _plain_ticks(ax)
    return ax.figure
