"""Which figures a result gets (`plot`), and writing them (`save`).

`plot` draws every figure that fits the result and says nothing about none: a quantity that is
NaN everywhere or has one value at every point gets no figure, with the reason recorded
(`Figures.skipped`, `why_not_drawn`). `save` draws each in memory first, then writes all of
them atomically, or none.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import re
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..errors import UserError
from ..files import new_file_mode, write_temporary
from .labels import _add_footer, _title
from .branches import plot_branches, stepped_axis
from .design import plot_design
from .envelope import BAND_DIM, plot_envelope
from .line import plot_line
from .maps import plot_map, plot_state_map
from .random import (peak_factors, plot_asd, plot_exceedance, plot_peak, plot_peak_factors,
                     plot_rms, random_axes)
from .result import (CLEARANCE_DIM, DIRECTION_DIM, _scene, _time_dim, check_result,
                     is_design_result, is_random_result, over_points, select_points,
                     swept_axes)
from .stability import (floquet_boundary_in_range, plot_growth_rate, plot_stability_chart,
                        plot_stability_over_map)
from .series import _snapshot_fields, plot_histories, plot_snapshots, plot_time_series
from .style import _log_ticks, _plain_ticks, _state_meaning, _unit

_log = logging.getLogger(__package__)     # "sweep.plot", the one logger of the figures


class Figures(dict):
    """The figures `plot` drew, by name (a dict), with the selection they were drawn for
    (`select`, written into the file names by `save`) and the figures left out with the
    reason (`skipped`: name -> why)."""

    def __init__(self, figures: Mapping[str, Figure] | None = None, *,
                 select: Mapping[str, Any] | None = None,
                 skipped: Mapping[str, str] | None = None) -> None:
        super().__init__(figures or {})
        self.select = dict(select or {})
        self.skipped = dict(skipped or {})


def why_not_drawn(da: xr.DataArray) -> str | None:
    """Why a figure of `da` would say nothing: every value NaN, or every finite value the same
    (e.g. settling times all 0 s); None when it varies."""
    v = np.asarray(da.values, dtype=float)
    finite = v[np.isfinite(v)]
    if not finite.size:
        return "no point has a value (all NaN)"
    if finite.min() == finite.max():
        factor, units = _unit(da, finite)
        value = f"{finite[0] * factor:.4g}" + (f" {units}" if units and units != "1" else "")
        some = " with a value" if finite.size < v.size else ""
        return f"every point{some} has the same value, {value}"
    return None


def plot(ds: xr.Dataset, select: Mapping[str, Any] | None = None) -> Figures:
    """Every figure that fits the result, keyed by name (the file name `save` gives it).

    Transverse: 'amplitude' and 'settling_time' (lines over one swept axis, maps over two),
    'max_strain' where clamps that hold rotation bend the span (the strain a design limits), and
    'absolute_acceleration_g' under base excitation; a continuous sine sweep also
    'peak_amplitude' and 'peak_frequency' over the axes, and with its envelope stored
    'envelope' (against the excitation frequency, zero or one swept axis) and 'envelope_map'
    (one swept axis x the bands);
    a continuous sine sweep run both ways ([base] sweep.direction = "both": a `direction`
    dimension) gets its up and down overlaid on the lines and the envelope, and each map twice,
    'NAME-up' and 'NAME-down', on one colour scale;
    'state' (map, two axes), 'time_series' (when stored); with outputs.stability
    'stability' (the Floquet Ince-Strutt chart over two axes, the growth rate against one) and,
    when the time-domain map exists too, 'stability_over_amplitude' (the amplitude map with the
    Floquet boundary over it); a stability-only result (no `state`) gets 'stability' alone.
    A random result ([base] asd_g2 / asd): its `realisation` is not a swept axis; 'rms',
    'peak', 'exceedance' (with outputs.clearance) and 'peaks' (`_random_figures`, random.py),
    and in place of the per-realisation quantities and the state map the means over the
    realisations: maps of 'rms_deflection_mean' and 'peak_deflection_mean' over two axes,
    'rms_acceleration_g_mean' and 'escape_probability' over one or two.
    Longitudinal: 'snapshots',
    'histories' (when stored), and 'peak_end_displacement', 'dynamic_amplification' over the
    swept axes. A quantity that says nothing (all NaN, or one value at every point, e.g. the
    settling times of an undamped run, all NaN; a state map with one state) gets no figure:
    the reason goes to `Figures.skipped` and the log (info here; `save` repeats it as a
    warning, which reaches stderr by default).
    Each figure has the load case in a footer (`footer`). An empty result when nothing fits.
    Raises UserError (one line) for a Dataset the figures cannot be drawn from faithfully
    (`check_result`), before drawing anything.
    """
    if not isinstance(ds, xr.Dataset):
        raise UserError(f"plot: {ds!r:.60} is not a result Dataset (open a file with "
                        "sweep.plot.load_result(PATH), or pass what sweep.run returned)")
    if is_design_result(ds):                   # 'sweep design -o': the design chart alone
        return _design_figures(ds, select)
    check_result(ds)
    if stepped_axis(ds) is not None:
        return _stepped_figures(ds, select)
    ds = select_points(ds, select)
    axes = swept_axes(ds)
    figures = Figures(select=select)
    random = is_random_result(ds)
    points = over_points(ds) if random else ds     # a random result: the means, per point
    if random:
        scalars = _RANDOM_SCALARS[:] if len(axes) == 2 else _RANDOM_SCALARS[2:]
    elif ds.attrs.get("model_kind") == "longitudinal":
        scalars = ["peak_end_displacement", "dynamic_amplification"]
    else:
        scalars = ["amplitude", "settling_time"]
        if "absolute_acceleration_g" in ds:        # base excitation (docs/model.md sec. 5)
            scalars.insert(1, "absolute_acceleration_g")
        if "max_strain" in ds and "clamp_bending_strain" in ds:   # clamps that hold rotation:
            scalars.insert(1, "max_strain")        # the strain where wires break (loads.py)
        if _is_swept(ds):                          # a continuous sine sweep: its peak first
            scalars[:0] = ["peak_amplitude", "peak_frequency"]
    if len(axes) == 2 and not random:
        scalars.append("state")
    for var in scalars:
        if var not in points or len(axes) not in (1, 2):
            continue
        if var == "state":
            reason = (f"every point is "
                      f"{_state_meaning(ds.isel({a: 0 for a in ds['state'].dims}))}"
                      if np.unique(ds["state"].values).size == 1 else None)
        else:
            reason = why_not_drawn(points[var])
        if reason is not None:
            figures.skipped[var] = reason
            _log.info("%s: %s: no figure (%s)", ds.attrs.get("title", "result"), var, reason)
        elif len(axes) == 1 and var != "state":
            figures[var] = plot_line(points, var).figure
        else:
            for key, way in _ways(ds, var):
                figures[key] = (plot_state_map(ds, direction=way) if var == "state"
                                else plot_map(points, var, direction=way)).figure
    if random:
        _random_figures(ds, figures)
    if "growth_rate" in ds:
        _stability_figures(ds, axes, figures)
    if "envelope" in ds:
        _envelope_figures(ds, axes, figures)
    if "displacement" in ds and _time_dim(ds["displacement"]) is not None:
        figures["time_series"] = plot_time_series(ds)
    if _snapshot_fields(ds):
        figures["snapshots"] = plot_snapshots(ds)
    if "end_displacement" in ds or "fixed_end_force" in ds:
        figures["histories"] = plot_histories(ds)
    for fig in figures.values():
        for ax in fig.axes:
            _plain_ticks(ax)
        _add_footer(fig, ds)
    return figures


_RANDOM_SCALARS = ["rms_deflection_mean", "peak_deflection_mean", "rms_acceleration_g_mean",
                   "escape_probability"]
"""A random result's per-point figures: means over the realisations (maps over two axes;
over one axis the deflections are on 'rms' and 'peak', so only the last two get lines)."""


def _random_figures(ds: xr.Dataset, figures: Figures) -> None:
    """A random result's own figures (random.py): 'rms' and 'peak' (means with their
    intervals against the swept axis, the linear RMS dashed, the clearance levels), 'exceedance'
    (with clearance levels) and 'peaks' (the peak factor's distribution over every record).
    Each is left out, with the reason, where its data are all NaN (every realisation escaped),
    where no axis is swept, or where the other axis has more values than one figure shows."""
    title = ds.attrs.get("title", "result")
    try:
        x, _level = random_axes(ds)
        too_many = None
    except UserError as exc:
        x, too_many = None, str(exc)
    drawn = {"rms": ("rms_deflection_mean", plot_rms),
             "peak": ("peak_deflection_mean", plot_peak),
             "exceedance": ("exceedance_probability", plot_exceedance),
             "peaks": ("peak_deflection", plot_peak_factors),
             "asd": ("acceleration_asd", plot_asd)}
    if CLEARANCE_DIM not in ds.dims:
        del drawn["exceedance"]
    for name, (var, draw) in drawn.items():
        if var not in ds:
            continue
        why = None if name == "asd" else too_many        # 'asd' picks its lines itself
        if why is None and x is None and name not in ("peaks", "asd"):   # these pool or pick
            why = "no swept axis with more than one value"
        if why is None and (not np.isfinite(np.asarray(ds[var].values, float)).any()
                            or name == "peaks" and not peak_factors(ds).size):
            why = "no point has a value (all NaN: every realisation escaped or failed)"
        if why is not None:
            figures.skipped[name] = why
            _log.info("%s: %s: no figure (%s)", title, name, why)
        else:
            figures[name] = draw(ds)


def _design_figures(ds: xr.Dataset, select: Mapping[str, Any] | None) -> Figures:
    """A design result's one figure, 'max_span' (`plot_design`), over the one axis `select`
    leaves (each selected value must be one of its axis's coordinates)."""
    for dim, value in (select or {}).items():
        if dim not in ds["max_span"].dims:
            raise UserError(f"--select {dim}={value:g}: the design result has no axis '{dim}' "
                            f"(its axes: {', '.join(map(str, ds['max_span'].dims)) or 'none'})")
        values = np.asarray(ds[dim].values, float)
        hit = np.flatnonzero(np.isclose(values, float(value), rtol=1e-9, atol=0.0))
        if hit.size == 0:
            raise UserError(f"--select {dim}={value:g}: not one of its values "
                            f"({', '.join(f'{v:g}' for v in values)})")
        ds = ds.isel({dim: int(hit[0])})
    return Figures({"max_span": plot_design(ds)}, select=select)


def _ways(ds: xr.Dataset, name: str) -> list[tuple[str, str | None]]:
    """The maps of `name`: one, (name, None); or, for a sweep run both ways (a `direction`
    dimension), one per direction, (name-up, 'up'), (name-down, 'down'). Two files rather than
    one drawing: each map keeps the layout (colour bar, state marks, overlays) of a map swept
    one way, and `plot_map` gives both one colour scale, so they compare colour for colour."""
    if DIRECTION_DIM not in ds["state"].dims:
        return [(name, None)]
    return [(f"{name}-{way}", str(way)) for way in ds[DIRECTION_DIM].values]


def _is_swept(ds: xr.Dataset) -> bool:
    """A continuous sine sweep's result ([base] sweep = {start, stop, rate})."""
    if "peak_frequency" in ds or "envelope" in ds:
        return True
    base = _scene(ds).get("base", {})
    return isinstance(base, dict) and isinstance(base.get("sweep"), dict)


def _envelope_figures(ds: xr.Dataset, axes: list[str], figures: Figures) -> None:
    """A sweep's 'envelope' (lines against the excitation frequency, `plot_envelope`; zero or
    one swept axis) and 'envelope_map' (its one swept axis x the bands, log frequency axis)."""
    title = ds.attrs.get("title", "result")
    names = ["envelope"] + (["envelope_map"] if len(axes) == 1 else [])
    reason = why_not_drawn(ds["envelope"])
    if reason is None and len(axes) > 1:
        example = " ".join(f"--select {d}={float(ds[d].values[0]):g}" for d in axes[1:])
        reason = (f"{len(axes)} swept axes ({', '.join(axes)}): select values of all but the "
                  f"first to draw it, e.g. {example}")
    if reason is None and ds.sizes[BAND_DIM] < 2:
        names = ["envelope"]
    for name in names:
        if reason is not None:
            figures.skipped[name] = reason
            _log.info("%s: %s: no figure (%s)", title, name, reason)
        elif name == "envelope":
            figures[name] = plot_envelope(ds)
        else:
            for key, way in _ways(ds, name):
                ax = plot_map(ds, "envelope", x=BAND_DIM, y=axes[0], xscale="log",
                              direction=way)
                ax.set_xlabel(f"excitation frequency [{ds[BAND_DIM].attrs.get('units', 'Hz')}]")
                ax.set_title(_title(ds, "response envelope" + (f", swept {way}" if way else "")),
                             fontsize="medium")
                _log_ticks(ax, "x")
                figures[key] = ax.figure


def _stability_figures(ds: xr.Dataset, axes: list[str], figures: Figures) -> None:
    """A stability result's 'stability' (the Ince-Strutt chart over two swept axes, the growth
    rate against one) and, when the result also has a time-domain map over the same axes,
    'stability_over_amplitude' (that map with the Floquet boundary over it)."""
    title = ds.attrs.get("title", "result")
    names = ["stability"] + (["stability_over_amplitude"]
                             if len(axes) == 2 and "state" in ds.data_vars else [])
    reason = why_not_drawn(ds["growth_rate"])
    if reason is None and len(axes) not in (1, 2):
        reason = "no swept axis with more than one value"
    if reason is None and sorted(ds["growth_rate"].dims) != sorted(axes):
        reason = (f"growth_rate lies over ({', '.join(ds['growth_rate'].dims)}), not over the "
                  f"swept axes ({', '.join(axes)})")
    for name in names:
        why = reason
        if why is None and name == "stability_over_amplitude":
            if DIRECTION_DIM in ds["state"].dims:
                why = "the time-domain maps were swept both ways; see the 'stability' chart"
            elif not floquet_boundary_in_range(ds):
                why = "the growth rate does not change sign: no Floquet boundary to draw"
        if why is not None:
            figures.skipped[name] = why
            _log.info("%s: %s: no figure (%s)", title, name, why)
        elif name == "stability":
            figures[name] = (plot_growth_rate(ds) if len(axes) == 1
                             else plot_stability_chart(ds))
        else:
            figures[name] = plot_stability_over_map(ds)


def _stepped_figures(ds: xr.Dataset, select: Mapping[str, Any] | None) -> Figures:
    """The figures of a stepped sweep: amplitude (and, under base excitation, the absolute
    acceleration in g) against the stepped axis, up and down with the jumps (`plot_branches`)."""
    figures = Figures(select=select)
    for var in ("amplitude", "absolute_acceleration_g"):
        if var not in ds:
            continue
        reason = why_not_drawn(ds[var])
        if reason is not None:
            figures.skipped[var] = reason
            continue
        figures[var] = plot_branches(ds, var, select=select).figure
    shown = select_points(ds, select)
    for fig in figures.values():
        for ax in fig.axes:
            _plain_ticks(ax)
        _add_footer(fig, shown)
    return figures


def _select_tag(select: Mapping[str, Any]) -> str:
    """'load_amplitude=4-length=0.5' for a selection, file-system safe (letters, digits and
    . _ = + - only)."""
    parts = []
    for dim, value in select.items():
        try:
            shown = f"{float(value):g}"
        except (TypeError, ValueError):
            shown = str(value)
        parts.append(re.sub(r"[^A-Za-z0-9._=+-]", "_", f"{dim}={shown}"))
    return "-".join(parts)


def save(figures: Mapping[str, Figure], directory: str | os.PathLike = ".",
         formats: Iterable[str] = ("png",), *, prefix: str = "", dpi: float = 100,
         select: Mapping[str, Any] | None = None) -> list[Path]:
    """Write each figure as DIRECTORY/PREFIX + key + .FORMAT (the directory is created);
    with a selection (`select`, else the one `plot` recorded on its `Figures`) the name is
    PREFIX + 'DIM=VALUE-' ... + key, so that figures of different selections do not overwrite
    each other (e.g. map-load_amplitude=4-amplitude.png). `dpi`: dots per inch of raster
    formats. The figures `plot` left out (`Figures.skipped`) are logged as warnings, one line
    each. Returns the paths written. Raises UserError for an unknown format or an
    unwritable directory."""
    select = getattr(figures, "select", None) if select is None else select
    tag = _select_tag(select) + "-" if select else ""
    formats = [f.strip().lower().lstrip(".") for f in formats if f.strip()]
    supported = Figure().canvas.get_supported_filetypes()
    for fmt in formats:
        if fmt not in supported:
            raise UserError(f"format '{fmt}': not a figure format matplotlib writes (use one of "
                            f"{', '.join(sorted(supported))})")
    out = Path(directory)
    # Every figure is drawn (in memory) before any file is written: a figure that fails to
    # draw leaves nothing behind.
    rendered = []
    for key, fig in figures.items():
        for fmt in formats:
            buffer = io.BytesIO()
            fig.savefig(buffer, format=fmt, dpi=dpi)
            rendered.append((out / f"{prefix}{tag}{key}.{fmt}", buffer.getvalue()))
    for key, reason in getattr(figures, "skipped", {}).items():
        _log.warning("%s%s%s: no figure (%s)", prefix, tag, key, reason)
    created = _make_directory(out)
    try:
        return _write_all(rendered)
    except BaseException:
        for path in reversed(created):
            with contextlib.suppress(OSError):
                path.rmdir()
        raise


def _make_directory(out: Path) -> list[Path]:
    """Create `out` and its missing parents; the directories created, outermost first."""
    missing = [p for p in (out, *out.parents) if not p.exists()][::-1]
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"output directory '{out}': could not be created "
                        f"({exc.strerror or exc})") from exc
    return missing


def _write_all(rendered: list[tuple[Path, bytes]]) -> list[Path]:
    """Write each (path, bytes) atomically: all to fresh temporary files in the target
    directory first (O_EXCL, unpredictable names, fsynced), then renamed over the targets.
    On any failure, removes every temporary and every file this call already renamed into
    place, and raises UserError naming the file (OSError) or re-raises."""
    mode = new_file_mode()
    temps: list[str] = []
    done: list[Path] = []
    path = None
    try:
        for path, data in rendered:
            temps.append(write_temporary(path.parent, f".{path.name}.", data, mode))
        for (path, _data), tmp in zip(rendered, temps):
            os.replace(tmp, path)
            done.append(path)
    except BaseException as exc:
        for name in temps:
            with contextlib.suppress(OSError):
                os.unlink(name)
        for written in done:
            with contextlib.suppress(OSError):
                written.unlink()
        if isinstance(exc, OSError):
            raise UserError(f"figure '{path}': could not be written ({exc.strerror or exc}); "
                            "no figure of this call was kept") from exc
        raise
    return done
