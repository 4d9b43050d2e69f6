"""The text on the figures: axis labels ('long_name [units]'), titles with the fixed axis
values, and the footer with the load case (model, end load, damping, initial state, span, end
time, solver, metrics) read from the result's `scene` attribute."""

from __future__ import annotations

import textwrap
from typing import Any, Iterable

import xarray as xr
from matplotlib.figure import Figure

from .overlays import overlays_for
from .result import _TIME_DIMS, DIRECTION_DIM, _scene, _setting
from .style import _fmt, _is_displacement

_MAX_LABEL = 60
_FOOTER_PT = 7.0


def label(da: xr.DataArray, units: str | None = None) -> str:
    """'long_name [units]' from the attributes (shortened: the text before ' (' when that is
    long, the variable name when still too long; no brackets for dimensionless '1', but [dB]
    for a level the long name gives in dB, which UDUNITS and so CF have no unit for)."""
    name = str(da.attrs.get("long_name") or da.name or "")
    if units is None and da.attrs.get("units") == "1" and " in dB" in name:
        units = "dB"
    if len(name) > 40 and " (" in name and name.index(" (") >= 10:
        name = name[:name.index(" (")]
    if len(name) > _MAX_LABEL:
        symbol = name.rsplit(", ", 1)[-1]        # a ratio's symbol, as "f/f1", kept
        name = str(da.name or name).replace("_", " ")
        if "/" in symbol and len(symbol) <= 8 and " " not in symbol:
            name += f", {symbol}"
    units = da.attrs.get("units") if units is None else units
    if units and name.endswith(f" in {units}"):        # not "... in g [g]"
        name = name[:-len(f" in {units}")]
    return f"{name} [{units}]" if units and units != "1" else name


POINT_DIM = "point"               # the dimension of a scene's [points] (sweep/scene/points.py)


def point_ticks(ax: Any, ds: xr.Dataset, which: str) -> None:
    """On the `which` ("x" or "y") axis of the point dimension: a tick per parameter set,
    labelled with its [points] values (the coordinates on that dimension), and the axis
    label naming them with their units."""
    if POINT_DIM not in ds.dims:
        return
    on = [c for c in ds.coords if c != POINT_DIM and ds[c].dims == (POINT_DIM,)]
    index = [int(i) for i in ds[POINT_DIM].values]

    def text(j: int) -> str:
        values = [f"{float(ds[c].values[j]):.3g}" for c in on]
        return f"{index[j]}\n" + ", ".join(values) if values else str(index[j])
    names = ", ".join(f"{c} [{ds[c].attrs['units']}]" if ds[c].attrs.get("units", "1") != "1"
                      else c for c in on)
    title = f"parameter set ({names})" if names else "parameter set"
    if which == "x":
        ax.set_xticks(index, [text(j) for j in range(len(index))], fontsize="small")
        ax.set_xlabel(title)
    else:
        ax.set_yticks(index, [text(j).replace("\n", ": ") for j in range(len(index))],
                      fontsize="small")
        ax.set_ylabel(title)
    ax.minorticks_off()


def _point_text(ds: xr.Dataset, dims: Iterable[str]) -> str:
    def one(d: str) -> str:
        factor, units = (1e3, "mm") if _is_displacement(ds[d]) else (1.0, ds[d].attrs.get("units"))
        value = f"{float(ds[d].values) * factor:.4g}"
        return f"{d} = {value} {units}" if units and units != "1" else f"{d} = {value}"
    return ", ".join(one(d) for d in dims)


def _title(ds: xr.Dataset, what: str = "") -> str:
    """The result's title plus the fixed (selected or single-valued) axis values."""
    fixed = [d for d in _scene_axes(ds) if d in ds.coords and ds[d].ndim == 0]
    parts = [str(ds.attrs.get("title", "cable-sweep result"))]
    if what:
        parts[0] += f": {what}"
    if fixed:
        parts.append(_point_text(ds, fixed))
    return ", ".join(parts)


def _scene_axes(ds: xr.Dataset) -> list[str]:
    doc = _scene(ds)
    return list(doc.get("axes", {})) if doc else [c for c in ds.coords
                                                 if c not in (*_TIME_DIMS, "snapshot_time",
                                                              "position", DIRECTION_DIM)]


def footer(ds: xr.Dataset) -> str:
    """The load case in one line, from the result's scene (its `scene` attribute) and fixed
    axis values: model, end load, damping, initial state, span, end time, solver, metrics.
    Swept quantities are left out (they are on the axes). Empty without a scene."""
    doc = _scene(ds)
    if not doc:
        return ""

    def get(section: str, key: str) -> Any:
        return _setting(ds, section, key)

    def num(value: Any) -> str:
        return f"{float(value):.4g}"

    parts = []
    load = doc.get("load", {})
    kind = doc.get("model", {}).get("kind", ds.attrs.get("model_kind", "transverse"))
    p0 = get("load", "amplitude")
    p0_ratio = get("load", "amplitude_ratio")
    text = f"{load.get('type', 'harmonic')} end load" + (
        f" P0 = {num(p0)} N" if p0 is not None else
        "" if p0_ratio is None else f" P0 = {num(p0_ratio)} Pcr")
    if p0 is not None and float(p0) == 0.0 and kind != "longitudinal":
        text = "no end load"
    elif load.get("type", "harmonic") == "harmonic" and kind != "longitudinal":
        ratio, freq = get("load", "frequency_ratio"), get("load", "frequency")
        if ratio is not None:
            text += f" at W/w1 = {num(ratio)}"
        elif freq is not None:
            text += f" at {num(freq)} Hz"
    parts.append(text)
    # What the result's model adds to the load case (base excitation: overlays._base_text).
    parts += [t for t in (text_of(ds, get) for text_of in overlays_for(ds, "footer")) if t]
    length = get("cable", "length")
    if length is not None:
        parts.append(f"l = {num(length)} m")
    solver = doc.get("solver", {})
    if kind == "longitudinal":
        parts.append("longitudinal wave, central difference")
        parts.append(f"{solver.get('intervals', '?')} intervals, "
                     f"C = {num(solver.get('courant', 1))}")
        if solver.get("transits") is not None:
            parts.append(f"{num(solver['transits'])} transits")
        elif solver.get("t_end") is not None:
            parts.append(f"t_end = {_fmt(float(solver['t_end']), 's')}")
        return "Load case: " + "; ".join(parts)
    model = doc.get("model", {})
    coeff = model.get("coefficients", ds.attrs.get("coefficients", "?"))
    text = f"{coeff} coefficients"
    if coeff == "paper":
        text += f" (cos terms {model.get('paper_parametric', 'printed')})"
    elif get("model", "membrane") is not None:
        text += f", membrane {num(get('model', 'membrane'))}"
    parts.insert(0, text)
    parts.insert(1, _ends_text(doc, get, num))
    zeta = get("cable", "damping_ratio")
    if zeta is not None:
        parts.append(f"damping ratio {num(zeta)}")
    if "state" not in ds.data_vars and "growth_rate" in ds.data_vars:
        # Stability only (no time-domain run): no initial state, end time, solver or metrics.
        modes = doc.get("model", {}).get("modes", 1)
        parts.append("Floquet multipliers of the straight span linearised about q = 0, one "
                     "load period per point" + (f", {modes} modes" if isinstance(modes, int)
                                                and modes > 1 else ""))
        return "Load case: " + "; ".join(parts)
    q0, v0 = get("initial", "displacement"), get("initial", "velocity")
    start = [t for t in ((None if q0 is None else f"q(0) = {_fmt(float(q0), 'm')}"),
                         (None if v0 is None else f"q'(0) = {num(v0)} m/s")) if t]
    if start:
        parts.append(", ".join(start))
    if solver.get("t_end") is not None:
        parts.append(f"t_end = {num(solver['t_end'])} s")
    parts.append(f"{solver.get('method', 'rk45')} rtol {num(solver.get('rtol', 1e-8))}")
    metrics = doc.get("metrics", {})
    if metrics:
        parts.append(f"tail {num(metrics.get('tail', 0.5))}, "
                     f"tolerance {num(metrics.get('tolerance', 0.02))}")
    return "Load case: " + "; ".join(parts)


def _ends_text(doc: dict, get: Any, num: Any) -> str:
    """What the clamps hold, for the footer: pinned, clamped or elastic ends (with k_t where
    it is fixed), and their axial restraint where the scene gives one (0: sliding)."""
    rotation = doc.get("clamps", {}).get("rotation", "pinned")
    text = {"pinned": "pinned ends", "clamped": "clamped ends"}.get(rotation, "elastic ends")
    stiffness = get("clamps", "rotational_stiffness")
    if rotation == "elastic" and stiffness is not None:
        text += f" (k_t = {num(stiffness)} N m/rad)"
    axial = get("clamps", "axial_stiffness")
    if axial is not None:
        text += (", sliding axially" if float(axial) == 0.0
                 else f", axial stiffness {num(axial)} N/m")
    return text


def _add_footer(fig: Figure, ds: xr.Dataset) -> None:
    """The footer under a constrained-layout figure, with room kept for it."""
    text = footer(ds)
    if not text:
        return
    width = fig.get_size_inches()[0]
    chars = max(40, int(width * 72.0 / (0.62 * _FOOTER_PT)))
    wrapped = _wrap(text, chars)
    lines = wrapped.count("\n") + 1
    height = (lines * 1.25 * _FOOTER_PT + 6.0) / 72.0 / fig.get_size_inches()[1]
    fig.text(0.01, 0.004, wrapped, fontsize=_FOOTER_PT, color="0.3", ha="left", va="bottom")
    engine = fig.get_layout_engine()
    if engine is not None and hasattr(engine, "set"):
        engine.set(rect=(0.0, height, 1.0, 1.0 - height))


def _wrap(text: str, width: int) -> str:
    return textwrap.fill(text, width, break_long_words=False)
