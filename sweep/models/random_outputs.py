"""What a random scene computes and stores (docs/model.md sec. 11): its inputs resolved once
(`RandomInputs`), the kernel settings of its statistics (`set_settings`), its records, and its
outputs as one table (`OUTPUTS`: each row a name, the kernel column it reads, units and long
name) plus what is made from them over the realisations.

Per grid point and realisation, over the statistics window (the record after the start-up
transient, sweep/models/random_scene.py): the RMS midspan deflection, velocity and absolute
acceleration, the up-crossing rate of zero, the peak |deflection| (`peak_deflection`), the peak
factor, and with outputs.clearance each level's up-crossing rate by |q|. Over the
realisations: each level's crossings pooled (`pooled_crossings`), the expected number of
exceedances in the test and the probability of at least one (Poisson: 1 - exp(-nu T)) from
the pooled rate nu; the mean of each statistic with a 95 % confidence half-width (Student's t),
the escape probability (the fraction of realisations that diverged: a softening span has no
stationary RMS), and beside them the exact linear RMS of the same span (stretching and end
load off) and the realised and specified grms of the input.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from sweep.kernels import layout as tk
from sweep.kernels import states as km

from ..dataset import derived
from ..schema import G2_UNITS, G_UNITS, STANDARD_GRAVITY
from . import random_scene
from .linear import linear_modes, receptance
from .random_scene import REALISATION_DIM

CLEARANCE_DIM = "clearance"
CONFIDENCE = 0.95
"""The confidence of the intervals on the means over realisations."""

OUTPUTS: tuple[tuple[str, int, str, str], ...] = (
    ("rms_deflection", tk.RMS_DEFLECTION, "m",
     "RMS midspan deflection over the statistics window"),
    ("rms_velocity", tk.RMS_VELOCITY, "m s-1",
     "RMS midspan velocity relative to the clamps over the statistics window"),
    ("rms_acceleration", tk.RMS_ACCELERATION, "m s-2",
     "RMS absolute midspan acceleration q'' + a_b over the statistics window"),
    ("rms_relative_acceleration", tk.RMS_RELATIVE, "m s-2",
     "RMS of the midspan deflection's second derivative q'' (relative to the clamps) over the "
     "statistics window"),
    ("zero_upcrossing_rate", tk.ZERO_RATE, "s-1",
     "up-crossings of zero by the midspan deflection per second"),
    ("statistics_window", tk.WINDOW, "s",
     "length of the statistics window: the record after the start-up transient"),
)
"""Per point and realisation: (variable, kernels.layout reals column, units, long name)."""
MEANS: tuple[str, ...] = ("rms_deflection", "rms_acceleration_g", "peak_deflection",
                          "peak_factor")
"""The statistics whose mean over the realisations is stored, with its confidence interval."""


@dataclass(frozen=True)
class RandomInputs:
    """A random scene's base acceleration, resolved once: spectrum (f Hz, W (m/s^2)^2/Hz) at
    0 dB; duration (s, each record); t_end (s, the run); sample_rate (Hz); realisations;
    seed; test_duration (s, for the expected exceedances); clearance (m, levels of |q|);
    ramp (s, base.ramp: the records' level rises over it; 0: none)."""
    spectrum: tuple[np.ndarray, np.ndarray]
    duration: float
    t_end: float
    sample_rate: float
    realisations: int
    seed: int
    test_duration: float
    clearance: tuple[float, ...]
    ramp: float = 0.0

    @classmethod
    def of(cls, values: dict[str, Any]) -> RandomInputs | None:
        """From a scene's resolved values; None where the scene is not random."""
        key = random_scene.spectrum_key(values)
        if key is None:
            return None
        from .random import spectrum
        duration = float(values["base.duration"])
        test = values.get("base.test_duration")
        return cls(spectrum=spectrum(values[key], key=key, per_g2=key == "base.asd_g2"),
                   duration=duration, t_end=float(values["solver.t_end"]),
                   sample_rate=random_scene.sample_rate(values),
                   realisations=int(values["base.realisations"]),
                   seed=int(values["base.seed"]),
                   test_duration=float(test) if test is not None else duration,
                   clearance=tuple(float(u) for u in values.get("outputs.clearance") or ()),
                   ramp=random_scene.ramp_time(values))

    def records(self, threads: int = 1) -> np.ndarray:
        """The records the kernels take as their `base` switch: (R, N, RECORD_ROWS) samples
        of a_b at 0 dB, their derivatives, running integrals and pieces
        (sweep/models/random.py, `Records`), made on `threads` threads (the same bits on any
        number)."""
        from .random import synthesise
        f, w = self.spectrum
        return synthesise(f, w, self.duration, self.sample_rate, self.realisations,
                          self.seed, threads).values


def set_settings(settings: np.ndarray, random: RandomInputs, coeffs: dict[str, Any],
                 params: dict[str, Any], tolerance: float) -> None:
    """A random scene's kernel settings: no settling time, and the clearance levels whose
    crossings the kernels count. The statistics window is metrics.tail's (TAIL, the whole run
    by default), each point's starting no earlier than its own start-up transient's end (its
    row's RECORD_START, sweep/models/modal.py); a point whose start-up outlasts the run is
    flagged invalid_input with a warning (`random_scene.warn_long_startups`), and a run in
    which no point has a window is refused (`random_scene.check_duration`)."""
    starts = random_scene.transient_time(2.0 * math.pi * coeffs["natural_frequency"],
                                         params["damping_ratio"], tolerance, random.ramp)
    random_scene.check_duration(random.t_end, float(np.min(np.asarray(starts, float))),
                                random.ramp)
    random_scene.warn_long_startups(random.t_end, starts)
    settings[tk.WANT_SETTLING] = 0.0
    settings[tk.N_LEVELS] = len(random.clearance)
    for k, level in enumerate(random.clearance):
        settings[tk.LEVEL_0 + k] = level


_Z_975 = 1.959963984540054     # the standard normal's 0.975 quantile (CONFIDENCE = 0.95)


def _t_factor(n: int) -> float:
    """Student's t quantile for a two-sided CONFIDENCE interval with n - 1 degrees of
    freedom (n >= 2), without SciPy at run time: a table to 30 degrees of freedom, beyond it
    the Cornish-Fisher expansion in 1 / (n - 1) to its fourth term (Abramowitz and Stegun
    26.7.5; within 1e-6 of the exact quantile there), which tends to the normal 1.96."""
    table = {2: 12.706, 3: 4.303, 4: 3.182, 5: 2.776, 6: 2.571, 7: 2.447, 8: 2.365, 9: 2.306,
             10: 2.262, 11: 2.228, 12: 2.201, 13: 2.179, 14: 2.160, 15: 2.145, 16: 2.131,
             17: 2.120, 18: 2.110, 19: 2.101, 20: 2.093, 21: 2.086, 22: 2.080, 23: 2.074,
             24: 2.069, 25: 2.064, 26: 2.060, 27: 2.056, 28: 2.052, 29: 2.048, 30: 2.045}
    if n in table:
        return table[n]
    z, nu = _Z_975, n - 1.0
    g1 = (z ** 3 + z) / 4.0
    g2 = (5 * z ** 5 + 16 * z ** 3 + 3 * z) / 96.0
    g3 = (3 * z ** 7 + 19 * z ** 5 + 17 * z ** 3 - 15 * z) / 384.0
    g4 = (79 * z ** 9 + 776 * z ** 7 + 1482 * z ** 5 - 1920 * z ** 3 - 945 * z) / 92160.0
    return z + g1 / nu + g2 / nu ** 2 + g3 / nu ** 3 + g4 / nu ** 4


_Z_95 = 1.6448536269514722     # the standard normal's 0.95 quantile (one-sided CONFIDENCE)


def poisson_upper(count: float) -> float:
    """The one-sided CONFIDENCE upper bound of a Poisson mean given `count` events seen (the
    mean m at which seeing `count` or fewer has probability 1 - CONFIDENCE; 2.996 for none,
    the "rule of three"): the chi-square quantile chi2(CONFIDENCE, 2 count + 2) / 2, without
    SciPy at run time. NaN for a count that is not a finite number >= 0."""
    if not (math.isfinite(count) and count >= 0.0):
        return math.nan
    return _poisson_upper(int(round(count)))


@functools.lru_cache(maxsize=4096)
def _poisson_upper(n: int) -> float:
    """`poisson_upper` of n events: by bisection on the Poisson distribution function up to
    200 events, beyond them the Wilson-Hilferty cube of the chi-square quantile (within 3e-6
    relative there)."""
    if n > 200:
        k = 2.0 * n + 2.0
        return 0.5 * k * (1.0 - 2.0 / (9.0 * k) + _Z_95 * math.sqrt(2.0 / (9.0 * k))) ** 3
    tail = 1.0 - CONFIDENCE

    def below(m: float) -> float:             # P(X <= n) for X ~ Poisson(m), m > 0
        terms = [k * math.log(m) - m - math.lgamma(k + 1.0) for k in range(n + 1)]
        top = max(terms)
        return math.exp(top) * sum(math.exp(t - top) for t in terms)

    lo, hi = float(n), float(n) + 10.0 * math.sqrt(n + 1.0) + 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if below(mid) > tail:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * hi:
            break
    return 0.5 * (lo + hi)


def mean_and_interval(values: xr.DataArray) -> tuple[xr.DataArray, xr.DataArray]:
    """The mean over the realisations of the finite values (a diverged realisation has none)
    and the half-width of its CONFIDENCE interval, t s / sqrt(n) (NaN with fewer than two)."""
    finite = values.where(np.isfinite(values))
    n = finite.count(REALISATION_DIM)
    mean = finite.mean(REALISATION_DIM)
    spread = finite.std(REALISATION_DIM, ddof=1) if values.sizes[REALISATION_DIM] > 1 \
        else xr.full_like(mean, np.nan)
    factor = xr.apply_ufunc(np.vectorize(lambda k: _t_factor(int(k)) if k >= 2 else np.nan,
                                         otypes=[float]), n)
    return mean, (factor * spread / np.sqrt(n.where(n > 0))).where(n >= 2)


def linear_rms(random: RandomInputs, coeffs: dict[str, Any], params: dict[str, Any],
               basis: Any, n_modes: int, coords: dict[str, xr.DataArray]) -> xr.DataArray:
    """The exact RMS midspan deflection (m) of the same span made linear (no stretching, no
    end load) under the same spectrum at each level: the root of the integral of
    |H(f)|^2 W(f) over the spectrum, H the midspan's receptance summed over the modes
    (`sweep.models.linear.linear_modes`; sweep/models/random.py `linear_mean_square`); on the
    axes it depends on."""
    from .random import linear_mean_square
    f, w = random.spectrum
    template, omega, damping, weights, level = linear_modes(coeffs, params, basis, n_modes,
                                                             coords)
    ms = linear_mean_square(f, w, omega, damping, weights)
    out = template.copy(data=np.sqrt(ms) * level.values)
    out.attrs = {"units": "m", "long_name": "exact RMS midspan deflection of the same span "
                 "made linear (no stretching, no end load) under the same spectrum, over the "
                 "modes the scene keeps (model.modes): beside rms_deflection, the "
                 "nonlinearity's effect"}
    return out


def linear_spectra(random: RandomInputs, coeffs: dict[str, Any], params: dict[str, Any],
                   basis: Any, n_modes: int, coords: dict[str, xr.DataArray],
                   frequency: xr.DataArray) -> dict[str, xr.DataArray]:
    """The exact spectral densities of the same span made linear, at `frequency` (Hz): the
    midspan deflection's |G|^2 W (m^2/Hz) and the absolute acceleration's |1 - w^2 G|^2 W
    (g^2/Hz), G(f) = -sum_n weights_n / (omega_n^2 - w^2 + i 2 zeta_n omega_n w) the
    midspan's receptance (`sweep.models.linear.linear_modes`), W the spectrum at the point's
    level."""
    from .random import asd_at
    f, w = random.spectrum
    template, omega, damping, weights, level = linear_modes(coeffs, params, basis, n_modes,
                                                             coords)
    nu = np.asarray(frequency.values, float)
    w_nu = 2.0 * np.pi * nu
    g = receptance(omega[..., None, :], damping[..., None, :], weights[..., None, :], w_nu)
    given = asd_at(nu, f, w) * (level.values[..., None] ** 2)
    dims = template.dims + tuple(frequency.dims)
    coords_ = {**{d: template[d] for d in template.dims if d in template.coords},
               **{d: frequency for d in frequency.dims}}
    deflection = xr.DataArray(np.abs(g) ** 2 * given, dims=dims, coords=coords_)
    acceleration = xr.DataArray(np.abs(1.0 - w_nu ** 2 * g) ** 2 * given
                                / STANDARD_GRAVITY ** 2, dims=dims, coords=coords_)
    return {"linear_deflection_asd": deflection.assign_attrs(
                units="m2 Hz-1", long_name="exact spectral density of the midspan deflection "
                "of the same span made linear (no stretching, no end load) under the same "
                "spectrum, at each bin's frequency: beside deflection_asd, the nonlinearity's "
                "effect where a resonance spans several bins (Welch's Hann window spreads a "
                "narrower one over about 4 bins: a finer outputs.asd_resolution compares it)"),
            "linear_acceleration_asd": acceleration.assign_attrs(
                units=G2_UNITS, long_name="exact spectral density of the absolute midspan "
                "acceleration of the same span made linear, in g^2/Hz: beside "
                "acceleration_asd")}


def spectral_moments(data: dict[str, xr.DataArray], n_modes: int,
                     loads: dict[str, xr.DataArray],
                     curvatures: dict[str, tuple[xr.DataArray, ...]] | None = None
                     ) -> dict[str, xr.DataArray]:
    """The midspan deflection's spectral moments m0 = E[q^2], m2 = E[q'^2], m4 = E[q''^2]
    (the squares of its RMS, its rate's and its second derivative's) and the irregularity
    factor m2 / sqrt(m0 m4) (1: narrow band); where the loads report a bending strain
    (`loads`: the loads' variables, sweep/models/loads.py), the RMS bending strain at the
    clamp and at midspan and its moments, for fatigue: with one mode, whose strains are
    proportional to q, the deflection's times the strain per metre squared; with several,
    the kernels' own mean squares of each curvature (`curvatures`: place -> its m0, m2, m4
    as strain^2, strain^2/s^2, strain^2/s^4)."""
    m0 = data["rms_deflection"] ** 2
    m2 = data["rms_velocity"] ** 2
    m4 = data["rms_relative_acceleration"] ** 2
    out = {}
    for order, value, units in ((0, m0, "m2"), (2, m2, "m2 s-2"), (4, m4, "m2 s-4")):
        out[f"deflection_m{order}"] = value.assign_attrs(
            units=units, long_name=f"spectral moment m{order} of the midspan deflection: the "
            f"mean square of its {['', '', 'rate', '', 'second derivative'][order] or 'value'}"
            " over the statistics window")
    with np.errstate(divide="ignore", invalid="ignore"):
        out["irregularity_factor"] = (m2 / np.sqrt(m0 * m4)).assign_attrs(
            units="1", long_name="irregularity factor m2 / sqrt(m0 m4) of the midspan "
            "deflection (1: narrow band, every zero crossing a peak)")
    for place in ("clamp", "midspan"):
        peak = loads.get(f"{place}_bending_strain")
        if peak is None:
            continue
        if n_modes == 1:
            with np.errstate(divide="ignore", invalid="ignore"):
                per_metre = peak / data["peak_deflection"]     # one mode: strain = c q
            moments = (per_metre ** 2 * m0, per_metre ** 2 * m2, per_metre ** 2 * m4)
            how = "one mode: proportional to the midspan deflection"
        elif curvatures is not None and place in curvatures:
            moments = curvatures[place]
            how = ("the modes' curvatures summed, their mean square integrated in the kernels"
                   + ("; at the clamp x = 0, whose statistics the other's share" if place ==
                      "clamp" else ""))
        else:
            continue
        out[f"rms_{place}_bending_strain"] = np.sqrt(moments[0]).assign_attrs(
            units="1", long_name=f"RMS outer-fibre bending strain at the {place} over the "
            f"statistics window ({how})")
        for order, value, units in zip((0, 2, 4), moments, ("1", "s-2", "s-4")):
            out[f"{place}_strain_m{order}"] = value.assign_attrs(
                units=units, long_name=f"spectral moment m{order} of the bending strain at "
                f"the {place} (for fatigue: narrow-band damage from m0 and m2, Dirlik's "
                "from m0 to m4 and m1)")
    return out


def realised_grms(records: np.ndarray, random: RandomInputs) -> np.ndarray:
    """Each record's RMS (g, at 0 dB) over the run [0, t_end] (s), from its samples, as the
    span is shaken: with base.ramp, the samples of its first `ramp` seconds at the ramp's
    level (1 - cos(pi t / ramp)) / 2."""
    last = int(math.floor(random.t_end * random.sample_rate))
    run = records[:, :last + 1, 0]
    if random.ramp > 0.0:
        t = np.arange(run.shape[1]) / random.sample_rate
        run = run * np.where(t < random.ramp, 0.5 - 0.5 * np.cos(np.pi * t / random.ramp), 1.0)
    return np.sqrt(np.mean(run * run, axis=1)) / STANDARD_GRAVITY


def pooled_crossings(rate: xr.DataArray, window: xr.DataArray, kept: xr.DataArray
                     ) -> tuple[xr.DataArray, xr.DataArray]:
    """(crossings counted, s of window observed): each realisation's up-crossing `rate` (1/s)
    times its statistics `window` (s), summed over the realisations where `kept`, and those
    windows' total. Their ratio is the rate of the stationary response over every record
    at once: a level that few records cross is estimated from all of them, where each
    record's own 1 - exp(-rate T) (0 where its window saw no crossing) averaged over the
    records underestimates the probability of a rare exceedance (Jensen's inequality). The
    count is NaN where no record observed anything (a point that never ran, or every record
    escaped or failed): not a count of 0."""
    usable = kept & np.isfinite(rate) & np.isfinite(window)
    observed = window.where(usable, 0.0).sum(REALISATION_DIM)
    counted = np.rint(rate * window).where(usable, 0.0).sum(REALISATION_DIM)
    return counted.where(observed > 0.0), observed     # NaN: no record observed the level


def _warn_startup_escapes(escaped: xr.DataArray, failed_at: xr.DataArray,
                          startup: Any, ramp: float, buckled: xr.DataArray) -> None:
    """Warn (one line) where realisations escaped in their point's start-up (`startup`, s:
    the ramp and the transient, random_scene.transient_time, the row's RECORD_START), before
    its statistics could start. A record switched on at full level at t = 0 on a span at rest
    gives a span whose first mode lies below the spectrum's band the base's velocity at t = 0
    as a kick of the transient's size (a reviewer: every escape of a span loaded to 0.95-0.98
    Pcr fell at 0.03-0.09 s, none later, and none with the same records ramped up over 1 s).
    escape_probability counts them; they say how the test starts, not how the span fares.
    Where a constant end load is at or past the buckling load (`buckled`), the straight span
    is unstable and leaves it at once: no ramp helps, and the warning says so."""
    import warnings

    from ..errors import CableSweepWarning
    early = escaped & (failed_at < startup)
    count = int(early.sum())
    if count == 0:
        return
    times = failed_at.where(early)
    if bool((early & buckled).any()):
        warnings.warn(f"{count} of {int(escaped.sum())} escaped realisations escaped in the "
                      f"start-up ({float(times.min()):.3g}-{float(times.max()):.3g} s): their "
                      "spans' constant end load is at or past the buckling load (load_ratio "
                      ">= 1), so the straight span is unstable and leaves it at once, whatever "
                      "the ramp; lower load.amplitude below buckling_load to shake a straight "
                      "span (docs/model.md sec. 11)", CableSweepWarning, stacklevel=5)
        return
    how = (f"the records rise over base.ramp = {ramp:g} s, and the kick is still there: a "
           "longer ramp eases it" if ramp > 0.0 else
           "the record starts at full level on a span at rest, which kicks a span whose first "
           "mode lies below the spectrum's band; bring the level up as a shaker does, e.g. "
           "base.ramp = 1.0 (s)")
    warnings.warn(f"{count} of {int(escaped.sum())} escaped realisations escaped in the "
                  f"start-up ({float(times.min()):.3g}-{float(times.max()):.3g} s, before "
                  f"their statistics start): {how}; escape_probability counts them "
                  "(docs/model.md sec. 11)", CableSweepWarning, stacklevel=5)


def outputs(reals: np.ndarray, states: np.ndarray, dims: tuple[str, ...],
            shape: tuple[int, ...], coords: dict[str, xr.DataArray], random: RandomInputs,
            coeffs: dict[str, Any], params: dict[str, Any], records: np.ndarray, basis: Any,
            n_modes: int, loads: dict[str, xr.DataArray] | None = None
            ) -> tuple[dict[str, xr.DataArray], dict[str, xr.DataArray]]:
    """The random outputs of a run (variables, extra coordinates): OUTPUTS, the acceleration
    in g, the peak factor, each MEANS statistic's mean and interval over the realisations,
    the escape probability, the clearance levels' rates and exceedances, the linear RMS and
    the input's grms. reals, states: the kernel's (grid order; the peak |q| over the window is
    reals' AMPLITUDE); loads: the span's load outputs (for the strains' moments)."""
    from .random import grms
    data: dict[str, xr.DataArray] = {}
    for name, column, units, long_name in OUTPUTS:
        data[name] = xr.DataArray(reals[:, column].reshape(shape), dims=dims,
                                  attrs={"units": units, "long_name": long_name})
    data["rms_acceleration_g"] = data["rms_acceleration"] / STANDARD_GRAVITY
    data["rms_acceleration_g"].attrs = {
        "units": G_UNITS, "long_name": "RMS absolute midspan acceleration in g "
                                       f"({STANDARD_GRAVITY:g} m s-2), grms"}
    peak = xr.DataArray(reals[:, tk.AMPLITUDE].reshape(shape), dims=dims, attrs={
        "units": "m", "long_name": "largest |midspan deflection| over the statistics window"})
    data["peak_deflection"] = peak
    with np.errstate(divide="ignore", invalid="ignore"):
        data["peak_factor"] = peak / data["rms_deflection"]
    data["peak_factor"].attrs = {"units": "1", "long_name": "peak factor: the largest "
                                 "|midspan deflection| over the window over its RMS"}
    for name in MEANS:
        source = data[name]
        mean, half = mean_and_interval(source)
        what = source.attrs["long_name"]
        data[f"{name}_mean"] = mean.assign_attrs(
            units=source.attrs["units"], long_name=f"mean over the realisations of: {what}")
        data[f"{name}_ci"] = half.assign_attrs(
            units=source.attrs["units"], long_name=f"half-width of the {CONFIDENCE:.0%} "
            f"confidence interval (Student's t) of {name}_mean")
    escaped = xr.DataArray((states == km.DIVERGED).reshape(shape), dims=dims)
    # a record with a verdict ran to its end or escaped (not one that never ran, or failed)
    decided = escaped | xr.DataArray((states == km.COMPLETED).reshape(shape), dims=dims)
    data["escape_probability"] = escaped.where(decided).mean(REALISATION_DIM).assign_attrs(
        units="1", long_name="fraction of the realisations in which the span escaped within "
        "the run: |q| reached the divergence bound (the span length unless "
        "metrics.divergence_bound says otherwise; a crossing of escape_barrier that comes "
        "back does not count), of those that ran to their end or escaped (NaN where none "
        "did): a softening span's measure, where an RMS means nothing")
    failed_at = xr.DataArray(reals[:, tk.FAILURE_TIME].reshape(shape), dims=dims)
    startup = random_scene.transient_time(
        2.0 * math.pi * derived(coeffs["natural_frequency"], coords),
        derived(params["damping_ratio"], coords), params["statistics_tolerance"], random.ramp)
    buckled = (derived(coeffs["load_ratio"], coords) >= 1.0) if params.get(
        "load_type") == "constant" else xr.DataArray(False)
    _warn_startup_escapes(escaped, failed_at, startup, random.ramp, buckled)
    data["escape_time_mean"] = failed_at.where(escaped).mean(REALISATION_DIM).assign_attrs(
        units="s", long_name="mean time of escape (divergence) over the realisations that "
        "escaped; NaN where none did")
    extra: dict[str, xr.DataArray] = {}
    if random.clearance:
        levels = xr.DataArray(np.array(random.clearance), dims=CLEARANCE_DIM,
                              attrs={"units": "m", "long_name": "clearance level of |midspan "
                                     "deflection| (outputs.clearance)"})
        extra[CLEARANCE_DIM] = levels
        n = len(random.clearance)
        rate = xr.DataArray(reals[:, tk.LEVEL_RATE:tk.LEVEL_RATE + n].reshape(shape + (n,)),
                            dims=dims + (CLEARANCE_DIM,))
        data["clearance_upcrossing_rate"] = rate.assign_attrs(
            units="s-1", long_name="up-crossings of the clearance level by |midspan "
            "deflection| per second over the statistics window")
        counted, observed = pooled_crossings(rate, data["statistics_window"], ~escaped)
        data["clearance_upcrossings"] = counted.assign_attrs(
            units="1", long_name="up-crossings of the clearance level by |midspan deflection| "
            "in the realisations that did not escape",
            comment="up-crossings of the clearance level by |midspan deflection| "
            "counted over the statistics windows of the realisations that did not escape (the "
            "count behind expected_exceedances: its relative standard error is at least "
            "1 / sqrt(count), and several times that where crossings come in clumps, as a "
            "narrow-band response crosses a high level on successive cycles)")
        with np.errstate(divide="ignore", invalid="ignore"):
            expected = counted / observed * random.test_duration
        data["expected_exceedances"] = expected.assign_attrs(
            units="1", long_name=f"expected number of exceedances of the clearance level in "
            f"the test ({random.test_duration:g} s): the up-crossing rate pooled over the "
            "realisations that did not escape (clearance_upcrossings over their windows' "
            "total length) times the test's duration")
        data["exceedance_probability"] = (1.0 - np.exp(-expected)).assign_attrs(
            units="1", long_name="probability that |midspan deflection| exceeds the "
            "clearance level at least once in the test, 1 - exp(-expected_exceedances) "
            "(Poisson crossings, Rice), from the pooled rate")
        upper = xr.apply_ufunc(np.vectorize(poisson_upper, otypes=[float]), counted)
        with np.errstate(divide="ignore", invalid="ignore"):
            upper_expected = upper / observed * random.test_duration
        data["exceedance_probability_upper"] = (1.0 - np.exp(-upper_expected)).assign_attrs(
            units="1", long_name=f"{CONFIDENCE:.0%} upper confidence bound of the "
            "probability of at least one exceedance in the test: 1 - exp(-nu T) with the pooled "
            "rate's one-sided upper bound, the count clearance_upcrossings taken as Poisson "
            "(with none counted, 3 over the windows' total length; crossings that come in "
            "clumps make the bound on the rate optimistic, while 1 - exp(-nu T) counts each "
            "crossing as a new exceedance, which errs high): what the records can vouch for "
            "where few or none crossed the level")
    curvatures = None
    if n_modes != 1 and loads:
        from .loads import strain_per_curvature
        factor = strain_per_curvature(params, coords) ** 2
        curvatures = {place: tuple((factor * xr.DataArray(
            reals[:, first + k].reshape(shape), dims=dims)).transpose(*dims) for k in range(3))
            for place, first in (("clamp", tk.CURVATURE_M0),
                                 ("midspan", tk.MID_CURVATURE_M0))}
    data.update(spectral_moments(data, n_modes, loads or {}, curvatures))
    data["linear_rms"] = linear_rms(random, coeffs, params, basis, n_modes, coords)
    f, w = random.spectrum
    level = derived(coeffs["base_accel"], coords)
    data["base_grms_spectrum"] = (level * grms(f, w)).assign_attrs(
        units=G_UNITS, long_name="RMS base acceleration of the spectrum at its level (grms: "
                                 "the root of its integral)")
    realised = xr.DataArray(realised_grms(records, random), dims=REALISATION_DIM)
    data["base_grms"] = (level * realised).assign_attrs(
        units=G_UNITS, long_name="RMS base acceleration of the record over the run (grms "
                                 "as realised and shaken: with base.ramp, its rise counted)")
    return data, extra
