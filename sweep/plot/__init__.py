"""Figures of a cable-sweep result: pick what fits the Dataset, draw it with matplotlib.

    from sweep.plot import plot, save
    figures = plot(ds)                       # {"amplitude": Figure, "state": Figure, ...}
    save(figures, "figs", formats=("png", "svg"), prefix="fig5-")

What `plot` draws, by the result's content:

- transverse, one swept axis: amplitude and settling time against it (`plot_line`), markers
  coloured by `state`;
- transverse, two swept axes: maps (`plot_map`) of amplitude and settling time with the
  modulated, unsettled, diverged and failed points marked, and a map of `state`
  (`plot_state_map`); closed-form overlays where the axes allow: the principal parametric
  resonance zone W = 2 w1 sqrt(1 +- mu), mu = P0/(2 Pcr) (docs/model.md sec. 2; dotted where
  damping suppresses it, mu < 2 zeta) and the buckling length where P0 = Pcr; under base
  excitation also a map of the absolute midspan acceleration in g and the linear resonance
  f = f1 (docs/model.md sec. 5);
- stored time series: q(t), one panel per point (`plot_time_series`, the paper's Fig 5);
- a stepped sweep ([continuation]): amplitude (and the absolute acceleration in g under base
  excitation) against the stepped axis, one curve per value of one other axis, stepped up solid
  and down dashed, the jumps marked by triangles (`plot_branches`);
- a continuous sine sweep ([base] sweep = {start, stop, rate}): peak_amplitude and
  peak_frequency over the axes like amplitude; with its envelope stored (outputs.envelope) the
  response envelope against the excitation frequency on log-log axes, one line per point of
  the one swept axis, each point's peak starred and its f1 dotted, the base level in g on a
  right axis (`plot_envelope`), and a map of the envelope over that axis and the bands (log
  frequency axis);
- a continuous sine sweep run both ways ([base] sweep.direction = "both", a `direction`
  dimension): up and down overlaid on every line (up solid, down dashed) and on the envelope
  (each point in its colour, both directions' peaks starred), and each map drawn once per
  direction (NAME-up, NAME-down) on one colour scale;
- a stability result (outputs.stability; with the time-domain outputs off it has no `state`
  and `stability`'s flags stand in for it): over two swept axes the Ince-Strutt chart
  ('stability', `plot_stability_chart`): the unstable points coloured by the Floquet growth
  rate (1/s), the stable ones light grey, invalid ones marked, the damped boundary (growth
  rate 0) outlined, the tongues m = 1, 2, 3, ... named at W/w1 = 2/m, and over W/w1 x P0/Pcr
  (a load_amplitude axis is drawn as P0/Pcr when `load_ratio` lies over it alone) the
  first-order boundaries of the undamped principal and second Mathieu zones; over one axis the
  growth rate against it with its zero line (`plot_growth_rate`); with the time-domain map
  too, that map with the Floquet boundary over it ('stability_over_amplitude',
  `plot_stability_over_map`, "Floquet: unstable inside");
- a random base excitation ([base] asd_g2 / asd, docs/model.md sec. 11): `realisation` (the
  Monte Carlo records) is a statistical dimension, not a swept axis; against the swept axis
  (span length when swept), one line per value of at most five of one other: the mean RMS
  midspan deflection over the records with its 95 % interval shaded and the exact linear RMS
  dashed ('rms', `plot_rms`), the mean peak deflection with the clearance levels ('peak',
  `plot_peak`), the probability of exceeding each clearance in the test ('exceedance',
  `plot_exceedance`), and the empirical distribution of peak / RMS over every record ('peaks',
  `plot_peak_factors`); the per-point figures draw the means over the records (maps of the
  mean RMS and peak deflection over two axes, the mean grms and escape probability), a point
  marked where one of its records did not complete;
- longitudinal: snapshots along the span (`plot_snapshots`, the paper's Fig 7) and the end
  histories (`plot_histories`); with swept axes also the peak end displacement and the
  dynamic amplification over them.

What every figure keeps to, so that it says something:

- a quantity that is NaN everywhere or has one value at every point (e.g. the settling times
  of an undamped run, all 0 s) gets no figure; `plot` records why (`Figures.skipped`) and
  `save` logs it;
- displacements are in mm on every axis, colour bar and label (times and forces get the
  prefix their size calls for); no axis uses an offset or a scientific multiplier, and
  near-constant data get a +-5 % range around their value;
- on a log-coloured displacement map, a cell below FLOOR (1e-3) times the map's largest
  value is drawn white, "no response", and the colours span the three decades above it;
- dense maps (more than 100 cells) mark the modulated, unsettled, diverged and failed points
  by hatched regions outlined along the cell edges, so the colour under them still shows;
- `plot` puts the load case (`footer`: model, P0, frequency, damping, initial state, t_end,
  solver, metrics; from the result's `scene` attribute) under each figure;
- on the paper's Fig 5 case (paper coefficients, P0 = 4 N, W/w0 = 1) the paper's amplitudes
  4.1, 3.8, 3.4, 3.0 mm (l = 0.5, 0.7, 0.85, 1 m) are marked "paper Fig 5".

More than two swept axes: `select={"dim": value, ...}` picks the values of the others (each
value must be one of the axis's coordinates); `save` writes the selection into the file names
(RESULT-DIM=VALUE-FIGURE.png), so that two selections do not overwrite each other. Labels read
`long_name` and `units` from the Dataset. Like xarray's plotting functions, the single-panel
ones take `ax=None` and return the Axes, and pass extra keyword arguments to matplotlib
(the stability figures, stability.py, take `ax=None` and return their Figure).
Figures are made with the object-oriented API (`matplotlib.figure.Figure`): no pyplot, no
display and no backend choice are needed, and none is forced on the caller.

The package, split like xarray's plot/ by what is drawn:
    result.py    reading and checking a result file, selecting points (no matplotlib)
    style.py     what every figure shares: state colours, units shown, ticks, edges, legends
    labels.py    axis labels, titles, the footer with the load case
    overlays.py  the closed-form overlays of each model kind, in one table (OVERLAYS)
    line.py      one swept axis (plot_line)
    maps.py      two swept axes (plot_map, plot_state_map)
    series.py    stored histories (plot_time_series, plot_snapshots, plot_histories)
    branches.py  a stepped sweep: up and down against the stepped axis, the jumps (plot_branches)
    design.py    a 'sweep design' result: max_span against its axis, by criterion (plot_design)
    stability.py Floquet stability: the Ince-Strutt chart, the growth rate, the boundary over a map
    envelope.py  a continuous sine sweep: the response envelope over frequency (plot_envelope)
    random.py    a random excitation: RMS, peak, exceedance and peak factors over the records
    figures.py   which figures a result gets, and writing them (plot, save)
"""

from __future__ import annotations

# _HATCHES, _edges and _select_tag are private; tests/test_plot.py reaches them here.
from .figures import Figures, _select_tag, plot, save, why_not_drawn  # noqa: F401
from .branches import plot_branches
from .design import plot_design
from .envelope import plot_envelope
from .labels import footer, label
from .line import plot_line
from .maps import _HATCHES, FLOOR, plot_map, plot_state_map  # noqa: F401
from .overlays import PAPER_FIG5_AMPLITUDES
from .random import plot_asd, plot_exceedance, plot_peak, plot_peak_factors, plot_rms
from .result import check_result, load_result, parse_select, select_points, swept_axes
from .series import plot_histories, plot_snapshots, plot_time_series
from .stability import plot_growth_rate, plot_stability_chart, plot_stability_over_map
from .style import STATE_STYLES, _edges, state_styles  # noqa: F401

__all__ = ["FLOOR", "Figures", "PAPER_FIG5_AMPLITUDES", "STATE_STYLES", "footer", "label",
           "check_result", "load_result", "parse_select", "plot", "plot_asd", "plot_branches",
           "plot_design",
           "plot_envelope", "plot_exceedance", "plot_growth_rate",
           "plot_histories",
           "plot_line", "plot_map", "plot_peak", "plot_peak_factors", "plot_rms",
           "plot_snapshots", "plot_state_map", "plot_time_series",
           "plot_stability_chart", "plot_stability_over_map",
           "save", "select_points", "state_styles", "swept_axes", "why_not_drawn"]
