"""The closed-form marks a figure gets from the physics of its result, per model kind.

A model's overlays live here, together (issue 18), and the drawing modules reach them through
one table, OVERLAYS: model kind -> figure -> the overlay functions that figure calls, in order.
Each function draws what the result allows and nothing otherwise (it checks the axes, the
coefficients, the load), so a figure calls every function its kind lists:

- transverse, line over length: the buckling length P0 = Pcr (dashed) and, on the paper's
  Fig 5 case, the paper's amplitudes 4.1, 3.8, 3.4, 3.0 mm ("paper Fig 5");
- transverse, maps: under base excitation the linear resonance f = f1 (docs/model.md sec. 5),
  the buckling length, and the principal parametric resonance zone W = 2 w1 sqrt(1 +- mu),
  mu = P0/(2 Pcr), dotted where damping suppresses it, mu < 2 zeta (docs/model.md sec. 2);
- transverse, stability chart (stability.py) over W/w1 x P0/Pcr: the first-order boundaries of
  the undamped principal and second Mathieu zones ("first-order boundaries (undamped)");
- transverse, time series: the paper's +-A of each Fig 5 span;
- transverse, footer: the base excitation ('base sine 1 g at 20 Hz');
- longitudinal, end histories of a single point: d'Alembert's peaks 2 P0 l/EA and 2 P0
  (docs/model.md sec. 4).

The signatures, by figure:
    "line"         f(ax, ds, dim, var, factor, units, size) -> legend handles
    "map"          f(ax, ds, x, y) -> legend handles
    "stability"    f(ax, ds, x, y) -> legend handles
    "time_series"  f(ax, ds, point, var, factor, units) -> None   (one panel)
    "histories"    f(ax, ds, points, name, factor) -> None        (one quantity)
    "footer"       f(ds, get) -> text or None                     (get: the scene value getter)
`factor` and `units`: how the figure shows the quantity (style._unit); `size`: marker size.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Iterable

import numpy as np
import xarray as xr
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.lines import Line2D

from .result import _scene, _setting
from .style import _OUTLINE, _coord, _fmt

# The paper's Fig 5 tail amplitudes [m] by span length [m] (P0 = 4 N, W/w0 = 1, Eq.32).
PAPER_FIG5_AMPLITUDES: dict[float, float] = {0.5: 4.1e-3, 0.7: 3.8e-3, 0.85: 3.4e-3,
                                             1.0: 3.0e-3}


def _kind(ds: xr.Dataset) -> str:
    """The result's model kind: its model_kind attribute, else its scene's model.kind
    (check_result has made sure the two agree), else transverse, the default."""
    return str(ds.attrs.get("model_kind") or _scene(ds).get("model", {}).get("kind")
               or "transverse")


def overlays_for(ds: xr.Dataset, figure: str) -> tuple[Callable[..., Any], ...]:
    """The overlay functions `figure` ("line", "map", "time_series", "histories", "footer")
    calls for this result, in order. A kind not in OVERLAYS is drawn as transverse."""
    return OVERLAYS.get(_kind(ds), OVERLAYS["transverse"]).get(figure, ())


# ---------------------------------------------------------------------------------- closed forms

def _paper_fig5(ds: xr.Dataset) -> dict[float, float]:
    """The paper's Fig 5 amplitudes [m] by span length for the points of this result, when it
    is the paper's Fig 5 case (paper coefficients, harmonic P0 = 4 N at W/w0 = 1, spans among
    0.5, 0.7, 0.85, 1 m); else empty."""
    if ds.attrs.get("coefficients") != "paper" or "length" not in ds.coords:
        return {}
    if _scene(ds).get("load", {}).get("type", "harmonic") != "harmonic":
        return {}
    p0, ratio = _setting(ds, "load", "amplitude"), _setting(ds, "load", "frequency_ratio")
    if p0 is None or ratio is None or not (math.isclose(float(p0), 4.0)
                                           and math.isclose(float(ratio), 1.0)):
        return {}
    found = {}
    for length in np.atleast_1d(ds["length"].values).astype(float):
        for paper_length, amplitude in PAPER_FIG5_AMPLITUDES.items():
            if math.isclose(length, paper_length, rel_tol=1e-6):
                found[float(length)] = amplitude
    return found


def _crossing(x: np.ndarray, y: np.ndarray, level: float) -> float | None:
    """The first x in the sampled range where y crosses `level` (log-log interpolation)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    for i in range(x.size - 1):
        a, b = y[i] - level, y[i + 1] - level
        if a == 0:
            return float(x[i])
        if a * b < 0:
            if min(x[i], x[i + 1], y[i], y[i + 1]) > 0:
                t = math.log(level / y[i]) / math.log(y[i + 1] / y[i])
                return float(x[i] * (x[i + 1] / x[i]) ** t)
            return float(x[i] + (x[i + 1] - x[i]) * (-a) / (b - a))
    return float(x[-1]) if y[-1] == level else None


def _depends_only_on(da: xr.DataArray, dims: Iterable[str]) -> bool:
    return set(da.dims) <= set(dims)


def _buckling_length(ds: xr.Dataset) -> float | None:
    """The span length where P0 = Pcr, when length is swept and P0/Pcr varies with it only."""
    if ds.attrs.get("model_kind") == "longitudinal" or "load_ratio" not in ds \
            or "length" not in ds.dims or ds["load_ratio"].dims != ("length",):
        return None
    return _crossing(ds["length"].values, ds["load_ratio"].values, 1.0)


def _damping(ds: xr.Dataset) -> Any:
    if "damping_ratio" in ds.coords:
        return ds["damping_ratio"]
    try:
        return float(_scene(ds)["cable"]["damping_ratio"])
    except (KeyError, TypeError, ValueError):
        return None


def _exact_peak(point: xr.Dataset, name: str) -> float | None:
    """d'Alembert's peak of a history, signed as the history runs (docs/model.md sec. 4)."""
    values = point[name].values
    finite = values[np.isfinite(values)]
    if not finite.size:
        return None
    sign = 1.0 if finite[np.argmax(np.abs(finite))] >= 0 else -1.0
    if name == "end_displacement" and "static_end_displacement" in point:
        return sign * 2.0 * abs(float(point["static_end_displacement"].values))
    if name == "fixed_end_force" and "peak_fixed_end_force" in point \
            and "force_amplification" in point:
        load = float(point["peak_fixed_end_force"].values) / float(
            point["force_amplification"].values)
        return sign * 2.0 * abs(load) if math.isfinite(load) else None
    return None


# ---------------------------------------------------------------------------------- transverse

def _buckling_line(ax: Axes, ds: xr.Dataset, dim: str, var: str, factor: float,
                   units: str | None, size: float) -> list:
    """A line over length: the buckling length P0 = Pcr, dashed, when it is in range."""
    if dim != "length":
        return []
    l_cr = _buckling_length(ds)
    if l_cr is None:
        return []
    ax.axvline(l_cr, color="k", ls="--", lw=1.0, zorder=2)
    return [Line2D([], [], color="k", ls="--", lw=1.0, label=f"P0 = Pcr, l = {l_cr:.3g} m")]


def _paper_fig5_points(ax: Axes, ds: xr.Dataset, dim: str, var: str, factor: float,
                       units: str | None, size: float) -> list:
    """The amplitude over length on the paper's Fig 5 case: the paper's amplitudes, hollow
    diamonds."""
    paper = _paper_fig5(ds) if dim == "length" and var == "amplitude" else {}
    if not paper:
        return []
    ax.scatter(list(paper), np.array(list(paper.values())) * factor, marker="D",
               s=size, facecolors="none", edgecolors="k", linewidths=1.2,
               zorder=4)
    return [Line2D([], [], ls="none", marker="D", markerfacecolor="none",
                   markeredgecolor="k", label="paper Fig 5: " + ", ".join(
                       f"{a * factor:g}" for a in paper.values()) + f" {units}")]


def _base_resonance(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """The linear resonance of a base-excited map: f = f1 over the other axis (a
    base_frequency axis, or a sweep's envelope bands `band_frequency`, when f1 depends on the
    other axis alone) or f/f1 = 1; its legend handle."""
    style = dict(color="w", lw=1.4, ls=(0, (1, 1.5)), zorder=3, path_effects=_OUTLINE)
    if "base_frequency_ratio" in (x, y):
        (ax.axvline if x == "base_frequency_ratio" else ax.axhline)(1.0, **style)
    elif ("base_frequency" in (x, y) or "band_frequency" in (x, y)) \
            and "natural_frequency" in ds:
        freq = "base_frequency" if "base_frequency" in (x, y) else "band_frequency"
        other = y if x == freq else x
        f1 = ds["natural_frequency"]
        if not _depends_only_on(f1, [other]) or other not in f1.dims:
            return []
        pos = _coord(ds, other)
        values = np.asarray(f1.transpose(other).values, float)
        px, py = (values, pos) if x == freq else (pos, values)
        ax.plot(px, py, **style)
    else:
        return []
    return [Line2D([], [], label="linear resonance f = f1", **style)]


def _buckling_map(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """A map over length: the buckling length P0 = Pcr, white dashes."""
    l_cr = _buckling_length(ds) if "length" in (x, y) else None
    if l_cr is None:
        return []
    (ax.axvline if x == "length" else ax.axhline)(l_cr, color="w", ls=(0, (4, 2)), lw=1.4,
                                                  zorder=3, path_effects=_OUTLINE)
    return [Line2D([], [], color="w", ls=(0, (4, 2)), lw=1.4, path_effects=_OUTLINE,
                   label=f"P0 = Pcr: l = {l_cr:.3g} m")]


def _resonance_zone(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """A map over a load frequency (consistent coefficients, harmonic load): the principal
    parametric resonance zone W = 2 w1 sqrt(1 +- mu), mu = P0/(2 Pcr), solid where it is
    active and dotted where damping suppresses it (mu < 2 zeta), when P0/Pcr, w1 and zeta
    vary with the other axis only (docs/model.md sec. 2)."""
    handles: list = []

    def draw(along: str, pos: np.ndarray, val: np.ndarray, **style: Any) -> None:
        # `pos` runs along the `along` axis; `val` is the other map coordinate.
        px, py = (pos, val) if along == x else (val, pos)
        ax.plot(px, py, **style)

    freq = next((f for f in ("frequency_ratio", "frequency") if f in (x, y)), None)
    is_harmonic = _scene(ds).get("load", {}).get("type", "harmonic") == "harmonic"
    if freq is None or ds.attrs.get("coefficients") != "consistent" or not is_harmonic \
            or "load_ratio" not in ds:
        return handles
    other = y if freq == x else x
    ratio = ds["load_ratio"]
    base = xr.DataArray(1.0) if freq == "frequency_ratio" else ds.get("natural_frequency")
    zeta = _damping(ds)
    parts = [ratio, base] + ([zeta] if isinstance(zeta, xr.DataArray) else [])
    if base is None or not all(_depends_only_on(p, [other]) for p in parts):
        return handles
    pos = _coord(ds, other)
    dense = np.geomspace(pos[0], pos[-1], 200) if pos[0] > 0 else np.linspace(pos[0], pos[-1], 200)

    def along(da: Any) -> np.ndarray:
        vals = np.broadcast_to(np.asarray(da.values if isinstance(da, xr.DataArray) else da,
                                          float), pos.shape)
        if np.all(vals > 0) and pos[0] > 0:
            return np.exp(np.interp(np.log(dense), np.log(pos), np.log(vals)))
        return np.interp(dense, pos, vals)

    mu = 0.5 * along(ratio)
    w1 = along(base)
    active = mu >= 2.0 * along(zeta) if zeta is not None else np.ones(dense.shape, bool)
    unit = "W/w1" if freq == "frequency_ratio" else "f"
    for sign in (1.0, -1.0):
        with np.errstate(invalid="ignore"):
            curve = 2.0 * w1 * np.sqrt(1.0 + sign * mu)
        on = np.where(active, curve, np.nan)
        off = np.where(active, np.nan, curve)
        # Join the solid and dotted parts where they meet.
        edge = np.flatnonzero(np.diff(active.astype(int)) != 0)
        off[edge] = curve[edge]
        off[edge + 1] = curve[edge + 1]
        draw(other, dense, on, color="w", lw=1.4, zorder=3, path_effects=_OUTLINE)
        draw(other, dense, off, color="w", lw=1.4, ls=":", zorder=3, path_effects=_OUTLINE)
    handles.append(Line2D([], [], color="w", lw=1.4, path_effects=_OUTLINE,
                          label=f"{unit} = 2 {'' if unit == 'W/w1' else 'f1 '}"
                                "sqrt(1 \u00b1 mu), mu = P0/2Pcr"))
    if not active.all():
        handles.append(Line2D([], [], color="w", lw=1.4, ls=":", path_effects=_OUTLINE,
                              label="damped out: mu < 2 zeta"))
    return handles


def _paper_fig5_bands(ax: Axes, ds: xr.Dataset, point: xr.Dataset, var: str, factor: float,
                      units: str | None) -> None:
    """A displacement panel of one of the paper's Fig 5 spans: its amplitude +-A, dashed."""
    paper = _paper_fig5(ds) if var == "displacement" else {}
    length = float(point["length"].values) if "length" in point.coords else None
    if length not in paper:
        return
    amplitude = paper[length] * factor
    for sign in (1.0, -1.0):
        ax.axhline(sign * amplitude, color="k", ls="--", lw=0.9,
                   label=f"paper Fig 5: \u00b1{amplitude:g} {units}" if sign > 0
                   else None)
    bottom, top = ax.get_ylim()          # headroom above the crests for the legend, so
    ax.set_ylim(bottom, max(top, 2.0 * amplitude))       # that it hides none of q(t)
    ax.legend(loc="upper right", fontsize="x-small", framealpha=0.9)


def _base_text(ds: xr.Dataset, get: Callable[[str, str], Any]) -> str | None:
    """'base sine 1 g at 20 Hz' for the footer of a base-excited result; swept parts left out
    (they are on the axes). None without base excitation."""
    doc = _scene(ds)
    if not ("absolute_acceleration_g" in ds or "base" in doc or any(
            str(a).startswith("base_") for a in doc.get("axes", {}))):
        return None
    base = doc.get("base") if isinstance(doc.get("base"), dict) else {}
    if "asd_g2" in base or "asd" in base:
        return _random_text(ds, base, get)
    level_g, level = get("base", "acceleration_g"), get("base", "acceleration")
    freq, ratio = get("base", "frequency"), get("base", "frequency_ratio")
    sweep = doc.get("base", {}).get("sweep") if isinstance(doc.get("base"), dict) else None
    if isinstance(sweep, dict) or any(str(a).startswith("base_sweep_") for a in doc.get(
            "axes", {})):
        return _sweep_text(ds, sweep if isinstance(sweep, dict) else {}, level_g, level)
    text = "base sine"
    if level_g is not None:
        text += f" {float(level_g):.4g} g"
    elif level is not None:
        text += f" {float(level):.4g} m/s^2"
    if freq is not None:
        text += f" at {float(freq):.4g} Hz"
    elif ratio is not None:
        text += f" at f/f1 = {float(ratio):.4g}"
    return text


def _random_text(ds: xr.Dataset, base: dict, get: Callable[[str, str], Any]) -> str:
    """'base random 20-2000 Hz, 14.1 grms, +0 dB, 8 records of 8 s' for a random result (its
    ASD's band, grms at the shown level, dB on the ASD, records); swept parts left out."""
    table = base.get("asd_g2", base.get("asd"))
    freqs = [_number(p[0]) for p in table if isinstance(p, (list, tuple)) and len(p) == 2] \
        if isinstance(table, list) else []
    freqs = [f for f in freqs if f is not None]
    text = "base random" + (f" {min(freqs):.4g}-{max(freqs):.4g} Hz" if freqs else "")
    grms = ds.get("base_grms_spectrum")
    if grms is not None and grms.ndim == 0 and _number(grms.values.item()) is not None:
        text += f", {float(grms.values):.3g} grms"
    scale = _number(get("base", "asd_scale"))
    if scale is not None:
        text += f" ({scale:+.3g} dB)"
    records, duration = _number(base.get("realisations")), _number(base.get("duration"))
    if records is not None and duration is not None:
        text += f", {int(records)} record{'s' if records != 1 else ''} of {duration:.4g} s"
    return text


def _number(value: Any) -> float | None:
    ok = isinstance(value, (int, float, np.number)) and not isinstance(value, bool)
    return float(value) if ok and math.isfinite(float(value)) else None


def _sweep_text(ds: xr.Dataset, sweep: dict, level_g: Any, level: Any) -> str:
    """'base sine sweep 20-60 Hz at 4 oct/min, 0.2-0.4 g (levels_g table)' (with ', swept up
    and down' or ', swept down' after the rate when sweep.direction says so); the swept parts
    left out (they are on the axes)."""
    def part(key: str) -> float | None:
        axis = f"base_sweep_{key}"
        if axis in ds.coords:
            return _number(ds[axis].values.item()) if ds[axis].ndim == 0 else None
        if axis in _scene(ds).get("axes", {}):
            return None
        return _number(sweep.get(key))

    start, stop, rate = part("start"), part("stop"), part("rate")
    text = "base sine sweep"
    if start is not None and stop is not None:
        text += f" {start:.4g}-{stop:.4g} Hz"
    elif start is not None or stop is not None:
        text += f" {'from' if start is not None else 'to'} {(start or stop):.4g} Hz"
    if rate is not None:
        text += f" at {rate:.4g} oct/min"
    way = sweep.get("direction")
    if way in ("up", "down", "both"):
        text += ", swept up and down" if way == "both" else f", swept {way}"
    table = _scene(ds).get("base", {}).get("levels_g")
    levels = [_number(p[1]) for p in table if isinstance(p, (list, tuple)) and len(p) == 2] \
        if isinstance(table, list) else []
    levels = [v for v in levels if v is not None]
    if levels:
        low, high = min(levels), max(levels)
        shown = f"{low:.4g} g" if low == high else f"{low:.4g}-{high:.4g} g"
        text += f", {shown} (levels_g table)"
    elif _number(level_g) is not None:
        text += f", {float(level_g):.4g} g"
    elif _number(level) is not None:
        text += f", {float(level):.4g} m/s^2"
    return text


MATHIEU_LABEL = "first-order boundaries (undamped)"
_MATHIEU_STYLE = dict(color="k", lw=1.2, ls=(0, (5, 2.5)), zorder=5,
                      path_effects=[patheffects.Stroke(linewidth=2.6, foreground="w"),
                                    patheffects.Normal()])


def mathieu_boundaries(mu: np.ndarray) -> dict[str, np.ndarray]:
    """W/w1 of the first-order boundaries of the undamped Mathieu zones at mu = P0/Pcr, from
    a = 4/r^2, s = 2 mu/r^2 (r = W/w1): the principal zone a = 1 -+ s, r = 2 sqrt(1 -+ mu/2);
    the second zone a = 4 - s^2/12 and a = 4 + 5 s^2/12, each a quadratic in r^2 solved at
    every mu: r^2 = (1 + sqrt(1 + mu^2/3))/2 and r^2 = (1 + sqrt(1 - 5 mu^2/3))/2 (the root
    near r = 1; NaN where there is none, mu > sqrt(3/5), far beyond first order)."""
    mu = np.asarray(mu, float)
    with np.errstate(invalid="ignore"):
        return {"principal_low": 2.0 * np.sqrt(1.0 - 0.5 * mu),
                "principal_high": 2.0 * np.sqrt(1.0 + 0.5 * mu),
                "second_high": np.sqrt(0.5 * (1.0 + np.sqrt(1.0 + mu ** 2 / 3.0))),
                "second_low": np.sqrt(0.5 * (1.0 + np.sqrt(1.0 - 5.0 * mu ** 2 / 3.0)))}


def _mathieu_zones(ax: Axes, ds: xr.Dataset, x: str, y: str) -> list:
    """A stability chart over W/w1 x P0/Pcr (a load_ratio axis, or load_amplitude with one
    buckling load): the first-order boundaries of the undamped principal and second zones
    (`mathieu_boundaries`), black dashes; nothing over other axes."""
    freq, other = (x, y) if x == "frequency_ratio" else (y, x)
    if freq != "frequency_ratio":
        return []
    if other == "load_ratio":
        to_mu = 1.0
    elif other == "load_amplitude" and "buckling_load" in ds and ds["buckling_load"].ndim == 0 \
            and float(ds["buckling_load"].values) > 0:
        to_mu = 1.0 / float(ds["buckling_load"].values)
    else:
        return []
    raw = np.asarray(ds[other].values, float)
    shown = _coord(ds, other)
    factor = float(shown[-1] / raw[-1]) if raw[-1] else 1.0
    load = np.linspace(raw.min(), raw.max(), 400)
    zones = mathieu_boundaries(load * to_mu)
    for name, r in zones.items():
        px, py = (r, load * factor) if x == freq else (load * factor, r)
        ax.plot(px, py, gid=f"mathieu-{name}", **_MATHIEU_STYLE)
    return [Line2D([], [], label=MATHIEU_LABEL, **_MATHIEU_STYLE)]


# ---------------------------------------------------------------------------------- longitudinal

def _exact_peaks(ax: Axes, ds: xr.Dataset, points: list[xr.Dataset], name: str,
                 factor: float) -> None:
    """The end history of a single point: d'Alembert's peak (2 P0 l/EA, 2 P0), dashed."""
    if len(points) != 1:
        return
    exact = _exact_peak(points[0], name)
    if exact is None:
        return
    formula = "2 P0 l/EA" if name == "end_displacement" else "2 P0"
    ax.axhline(exact * factor, color="0.3", ls="--", lw=0.9,
               label=f"exact peak {formula} = "
                     f"{_fmt(abs(exact), ds[name].attrs.get('units'))}")


# model kind -> figure -> its overlay functions, drawn in this order (signatures: see above).
OVERLAYS: dict[str, dict[str, tuple[Callable[..., Any], ...]]] = {
    "transverse": {"line": (_buckling_line, _paper_fig5_points),
                   "map": (_base_resonance, _buckling_map, _resonance_zone),
                   "stability": (_mathieu_zones,),
                   "time_series": (_paper_fig5_bands,),
                   "footer": (_base_text,)},
    "longitudinal": {"histories": (_exact_peaks,)},
}
