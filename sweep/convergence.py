"""Is N modes enough? Run a transverse scene with N and N + 2 Galerkin modes and compare.

    sweep modes SCENE [--modes N] [--set KEY=VALUE ...] [--tolerance 0.01]

The odd modes are the ones a symmetric load drives (base excitation; an even mode takes part
only through a parametric instability of its own), so the check adds two modes, the next odd
one among them (docs/model.md sec. 7). For every metric of the result (amplitude, peak
amplitude, settling time, response period, absolute acceleration, transmissibility, a
sweep's peak frequency and envelope, a stability chart's growth rate and multiplier, and each
modal amplitude the coarse run has) it reports the largest relative change
|x(N + 2) - x(N)| / |x(N + 2)| over the grid points where both runs succeeded, where on the
grid that is, and at how many points the change exceeds the tolerance; points whose state changed are counted apart. The tail
window's metrics (TAIL_METRICS) are not compared at points that decayed in either run. A modal
amplitude's change is taken relative to the point's largest modal amplitude (a mode at rest,
round-off in both runs, does not count). N is enough for a tolerance when something was
compared and every change is within it; with nothing compared there is no verdict.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
import xarray as xr

from .errors import UserError
from .models.loads import NAMES
from .schema import BY_DOTTED

METRICS = ("amplitude", "peak_amplitude", "settling_time", "response_period",
           "absolute_acceleration", "transmissibility", "peak_frequency", "envelope",
           "growth_rate", "floquet_multiplier", "modal_amplitude", "max_deflection",
           "rms_deflection_mean", "rms_acceleration_g_mean", "peak_deflection_mean") + NAMES
"""The result variables compared, where both runs have them: the time-domain metrics of
every kind of run (fixed frequency, stepped, swept: its peak, peak frequency and envelope)
and a stability chart's Floquet results; a random result's means over its records (RMS and
peak deflection, RMS acceleration; their intervals say how far sampling alone moves them);
every load output of the span (sweep.models.loads:
the bending at the clamps converges more slowly with the modes than the midspan, the shape
sharpens there; clamp_force carries the base inertia the modes leave out, and converges
about as fast as the midspan)."""
SUCCESS_STATES = ("decayed", "steady", "modulated", "unsettled", "completed")
"""States whose metrics mean something (the failure states have NaN metrics)."""
TAIL_METRICS = ("amplitude", "response_period", "absolute_acceleration", "modal_amplitude",
                "max_deflection") + NAMES
"""Metrics of the tail window, not compared where either run decayed: a decayed point's tail
is below metrics.tolerance x its peak by definition, and what is left of it there (its rate
of decay, round-off near the absolute tolerance) is no answer to compare."""


@dataclass(frozen=True)
class Change:
    """One metric's largest relative change between the coarse and the fine run.

    metric: the variable (with the mode for modal amplitudes, e.g. "modal_amplitude[mode=1]");
    relative: the largest |fine - coarse| / |fine| (1; NaN where no point has both values);
    where: the grid point of it, axis name -> value; compared: the points compared; over: how
    many of them changed by more than the Report's tolerance.
    """
    metric: str
    relative: float
    where: dict[str, Any]
    compared: int
    over: int


@dataclass(frozen=True)
class Report:
    """The comparison of a scene's result with n_modes and with n_modes + 2 modes, against a
    relative tolerance."""
    n_modes: int
    tolerance: float
    changes: list[Change]
    state_changes: int       # grid points whose state differs between the two runs
    points: int

    def compared(self) -> bool:
        """Whether any metric was compared at any point (a verdict needs something)."""
        return any(c.compared > 0 for c in self.changes)

    def enough(self) -> bool:
        """Whether something was compared, every metric changed by at most the tolerance
        (relative) and no state did."""
        return (self.compared() and self.state_changes == 0
                and all(c.over == 0 for c in self.changes))

    def text(self) -> str:
        """The report as a short table for a terminal."""
        fine, tolerance = self.n_modes + 2, self.tolerance
        lines = [f"modes {self.n_modes} against {fine}, {self.points} point"
                 f"{'s' if self.points != 1 else ''}: the largest relative change of each "
                 f"metric, where, and at how many points it exceeds {tolerance:g}",
                 f"  {'metric':<28} {'largest':>9}  {'over':>9}  where"]
        for c in self.changes:
            where = ", ".join(f"{k}={_short(v)}" for k, v in c.where.items()) or "-"
            value = "n/a" if math.isnan(c.relative) else f"{c.relative:.2e}"
            lines.append(f"  {c.metric:<28} {value:>9}  {c.over:>4}/{c.compared:<4}  {where}")
        if self.state_changes:
            lines.append(f"  state changed at {self.state_changes} of {self.points} points")
        modes = f"{self.n_modes} mode{'s' if self.n_modes != 1 else ''}"
        if not self.compared():
            lines.append(f"{modes}: no verdict: no metric could be compared at any point "
                         "(every point failed in one of the runs, or the result holds none of "
                         f"{', '.join(METRICS)})")
        elif self.enough():
            lines.append(f"{modes}: enough for {tolerance:g} relative (every metric within it "
                         "at every point, no state change)")
        else:
            worse = [c.metric for c in self.changes if c.over]
            why = ", ".join(worse + (["the state"] if self.state_changes else []))
            lines.append(f"{modes}: NOT enough for {tolerance:g} relative everywhere ({why} "
                         f"changed by more somewhere; 'sweep modes --modes {fine}' checks "
                         f"{fine})")
        return "\n".join(lines)


def _plain(value: Any) -> Any:
    """A coordinate value as a Python scalar (a number, or a label such as 'up')."""
    return value.item() if hasattr(value, "item") else value


def _short(value: Any) -> str:
    return f"{value:.6g}" if isinstance(value, (float, np.floating)) else str(value)


def compare(coarse: xr.Dataset, fine: xr.Dataset, tolerance: float = 0.01) -> Report:
    """The Report of two results of one scene, with N (coarse) and N + 2 (fine) modes."""
    n_modes = coarse.sizes.get("mode", 1)
    if "state" in coarse and "state" in fine:
        meanings = coarse["state"].attrs["flag_meanings"].split()
        flags = np.atleast_1d(coarse["state"].attrs["flag_values"])
        ok = [int(f) for f, m in zip(flags, meanings) if m in SUCCESS_STATES]
        both = coarse["state"].isin(ok) & fine["state"].isin(ok)
        decayed = [int(f) for f, m in zip(flags, meanings) if m == "decayed"]
        live = both & ~coarse["state"].isin(decayed) & ~fine["state"].isin(decayed)
        state_changes = int((coarse["state"] != fine["state"]).sum())
        points = int(np.prod(coarse["state"].shape))
    else:                  # no time-domain run (a stability chart): every point compared
        grid = [d for d in coarse.dims if d in coarse.coords and d != "mode"]
        both = live = xr.DataArray(np.ones([coarse.sizes[d] for d in grid], bool), dims=grid,
                                   coords={d: coarse[d] for d in grid})
        state_changes, points = 0, int(both.size)
    changes = []
    for name in METRICS:
        if name not in coarse or name not in fine:
            continue
        a, b = coarse[name], fine[name]
        mask = live if name in TAIL_METRICS else both
        # a statistic over the records (a random result's mean) is compared once per point,
        # where every record succeeded, not once per record
        over = [d for d in mask.dims if d not in a.dims]
        mask = mask.all(over) if over else mask
        if "mode" in a.dims:
            # relative to the point's largest modal amplitude: a mode at rest (an even one under
            # base excitation, round-off on both sides) changes by nothing that matters
            scale = b.max("mode")
            for n in a["mode"].values:
                changes.append(_change(f"{name}[mode={n}]", a.sel(mode=n), b.sel(mode=n), mask,
                                       tolerance, scale))
        else:
            changes.append(_change(name, a, b, mask, tolerance))
    return Report(n_modes, tolerance, changes, state_changes, points)


def _change(metric: str, coarse: xr.DataArray, fine: xr.DataArray, mask: xr.DataArray,
            tolerance: float, scale: xr.DataArray | None = None) -> Change:
    """The largest relative change of one variable over the points of `mask`: |fine - coarse|
    over |fine|, or over `scale` where given."""
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = (abs(fine - coarse) / abs(fine if scale is None else scale)).where(
            mask & np.isfinite(coarse) & np.isfinite(fine))
        rel = rel.where(~((fine == 0) & (coarse == 0)), 0.0).where(mask)
    values = rel.values
    finite = np.isfinite(values)
    if not finite.any():
        return Change(metric, math.nan, {}, 0, 0)
    index = np.unravel_index(int(np.nanargmax(np.where(finite, values, -1.0))), values.shape)
    where = {d: _plain(rel[d].values[i]) for d, i in zip(rel.dims, index) if d in rel.coords}
    return Change(metric, float(values[index]), where, int(finite.sum()),
                  int((values[finite] > tolerance).sum()))


def overrides_for(scene: Any, n_modes: int) -> dict[str, Any]:
    """The scene key overrides that run `scene` (a Scene) with n_modes modes: model.modes, and
    the modal initial-condition lists padded with zeros (the added modes start at rest)."""
    out: dict[str, Any] = {"model.modes": n_modes}
    for dotted in ("initial.modal_displacement", "initial.modal_velocity"):
        values = scene.get(dotted)
        if values is not None:
            if len(values) > n_modes:
                raise UserError(f"scene key '{dotted}': has {len(values)} entries, more than "
                                f"the {n_modes} modes compared (give --modes {len(values)} "
                                "or more)")
            out[dotted] = list(values) + [0.0] * (n_modes - len(values))
    return out


def mode_convergence(source: str, overrides: Mapping[str, Any] | None = None,
                     n_modes: int | None = None, threads: int | None = None,
                     progress: bool | None = None, tolerance: float = 0.01
                     ) -> tuple[Report, xr.Dataset, xr.Dataset]:
    """Run the scene `source` (a built-in name or a .toml file, with `overrides`) with n_modes
    (default: the scene's model.modes) and n_modes + 2 modes; returns the Report (against the
    relative `tolerance`) and both results."""
    from .run import run
    from .scene import load_scene
    overrides = dict(overrides or {})
    scene = load_scene(source, overrides=overrides)
    if scene.get("model.kind") != "transverse":
        raise UserError(f"scene '{source}': model.kind = '{scene.get('model.kind')}' has no "
                        "modes to compare (the mode check is for transverse scenes)")
    if scene.get("model.coefficients") == "paper":
        raise UserError(f"scene '{source}': model.coefficients = 'paper' is the paper's one-mode "
                        "Eq.32, so there are no more modes to compare (use model.coefficients "
                        "= 'consistent' to check the modes)")
    n = n_modes if n_modes is not None else scene.get("model.modes")
    most = int(BY_DOTTED["model.modes"].maximum)
    if not 1 <= n <= most - 2:
        raise UserError(f"--modes {n}: the check runs {n} and {n + 2} modes, and model.modes "
                        f"is 1 to {most} (give --modes 1 to {most - 2})")
    # both scenes read (and a refusal of either said) before anything runs
    scenes = [load_scene(source, overrides={**overrides, **overrides_for(scene, count)})
              for count in (n, n + 2)]
    results = [run(resolved, threads=threads, progress=progress) for resolved in scenes]
    return compare(results[0], results[1], tolerance), results[0], results[1]
