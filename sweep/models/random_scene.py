"""The scene rules of a random base acceleration (docs/model.md sec. 11): which keys it takes
and refuses, its defaults, and how long its start-up transient lasts. The spectrum and its
records are sweep/models/random.py's; the kernel settings and the outputs
sweep/models/random_outputs.py's.

A scene is random when it gives ``base.asd_g2`` (g^2/Hz) or ``base.asd`` ((m/s^2)^2/Hz): the
records replace the sine ([base] acceleration, frequency, sweep and levels_g are refused with
them), every grid point sees the same ``base.realisations`` records (a ``realisation``
dimension), the run ends with the record (``base.duration``; ``solver.t_end`` may be shorter,
never longer: the record is periodic), and the statistics are taken after the start-up
transient has decayed (`transient_time`; a point whose start-up outlasts the run is flagged
invalid_input, `warn_long_startups`). With ``base.rms_accuracy`` a scene whose realisations
are too few for that accuracy at some point is refused, with the count that reaches it
(`check_accuracy`).
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from sweep.kernels import layout as tk        # plain constants: no Numba is imported

from .. import schema
from ..scene.messages import _fail, _show

RANDOM_KEYS: tuple[str, str] = ("base.asd_g2", "base.asd")
"""The two spellings of the spectrum (g^2/Hz and (m/s^2)^2/Hz)."""
RANDOM_ONLY: tuple[str, ...] = ("base.asd_scale", "base.duration", "base.realisations",
                                "base.seed", "base.sample_rate", "base.test_duration", "base.ramp",
                                "base.rms_accuracy", "outputs.clearance",
                                "outputs.response_asd", "outputs.asd_resolution")
"""Keys that mean something only with a spectrum."""
SINE_KEYS: tuple[str, ...] = ("base.acceleration", "base.acceleration_g", "base.levels_g",
                              "base.frequency", "base.frequency_ratio", "base.sweep.start",
                              "base.sweep.stop", "base.sweep.rate", "base.sweep.ramp_cycles",
                              "base.sweep.direction")
MAX_LEVELS = tk.MAX_LEVELS
"""Most clearance levels: the kernels count the crossings of this many."""
REALISATION_DIM = "realisation"
DEFAULT_RTOL = 1e-5
"""solver.rtol of a random scene that gives none. Its RMS is a statistic whose error over a
record is about 1 % or more (docs/model.md sec. 11, "How long a record"); at 1e-5 DOP853
integrates each record's RMS to 5e-4 or better in every case of the work-precision table
whose trajectories converge (benchmarks/RESULTS.md, "The random scene's tolerance"; 7.4e-4
against SciPy on benchmarks/random_cost.py's 1 s record; a reviewer's worst, 3e-3, on a
200 mm record at -20 dB), still far inside a record's statistical error, and runs the
built-in scene 1.4x (one mode) to 1.5x (three) faster than at 1e-6. Where the trajectories
are chaotic (every point of the built-in scene) only the means over records converge, and
those at 1e-5 and 1e-9 agree within their intervals."""


def spectrum_key(values: Mapping[str, Any]) -> str | None:
    """Which spelling of the spectrum a scene gives (values or given keys), or None."""
    return next((k for k in RANDOM_KEYS if values.get(k) is not None), None)


def is_random(values: Mapping[str, Any]) -> bool:
    """Whether a scene's base excitation is a random record (a spectrum is given)."""
    return spectrum_key(values) is not None


def _present(dotted: str, given: Mapping[str, Any], axes: Mapping[str, Any]) -> bool:
    """Whether a scene gives the key (a switch turned off, as a resolved scene writes
    outputs.response_asd = false, is not given) or sweeps it."""
    axis = schema.BY_DOTTED[dotted].axis
    return ((dotted in given and given[dotted] is not False)
            or (axis is not None and axis in axes))


def check(given: dict[str, Any], axes: Mapping[str, Any]) -> None:
    """Refuse what a random scene cannot take, and random keys without a spectrum (given:
    dotted key -> value, before defaults; axes: axis name -> values)."""
    if not is_random(given):
        for dotted in RANDOM_ONLY:
            if _present(dotted, given, axes):
                _fail(f"scene key '{dotted}'", "only for a random base acceleration",
                      "give its spectrum, [base] asd_g2 = [[20.0, 0.026], [50.0, 0.16], "
                      "[800.0, 0.16], [2000.0, 0.026]] (Hz, g^2/Hz), or remove the key")
        return
    if all(k in given for k in RANDOM_KEYS):
        _fail("scene keys 'base.asd_g2' and 'base.asd'", "give one, not both",
              "remove one of them: asd_g2 is in g^2/Hz, asd in (m/s^2)^2/Hz")
    key = spectrum_key(given)
    for dotted in SINE_KEYS:
        if _present(dotted, given, axes):
            _fail(f"scene key '{dotted}'", f"a random base acceleration ({key}) replaces the "
                  "sine excitation", f"remove {dotted}, or remove {key} for a sine")
    if given.get("model.kind") == "longitudinal":
        _fail(f"scene key '{key}'", "model.kind = 'longitudinal' has no base excitation",
              "remove the spectrum, or use model.kind = 'transverse'")
    if given.get("model.coefficients") == "paper":
        _fail(f"scene key '{key}'", "model.coefficients = 'paper' has no base excitation "
              "(Eq.32 as printed has no forcing term)", "use model.coefficients = 'consistent'")
    if given.get("base.duration") is None:
        _fail("scene section '[base]'", f"a random base acceleration ({key}) needs "
              "base.duration, each record's length in seconds",
              "add duration = 20.0 (s) to [base]; 1 % on the RMS of a 100 Hz span with "
              "2 % damping takes about 200 s of records (base.realisations x duration)")
    refused = (("continuation.axis", "a stepped sweep steps a sine's frequency",
                "remove [continuation]"),
               ("solver.stop_when_steady", "a random response is never steady",
                "remove it"),
               ("outputs.settling_time", "a random response has no settling time",
                "remove it: a random scene stores RMS, peaks and crossing rates"),
               ("outputs.stability", "the Floquet chart is the unforced span's",
                "run it in a scene without the spectrum"),
               ("outputs.envelope", "the envelope is a sine sweep's", "remove it"))
    for dotted, why, fix in refused:
        if given.get(dotted) not in (None, False):
            _fail(f"scene key '{dotted}'", f"{why} ({key} is a random base acceleration)", fix)
    duration = given["base.duration"]
    t_end = given.get("solver.t_end")
    if t_end is not None and t_end > duration:
        _fail("scene key 'solver.t_end'", f"{_show(t_end)} s is longer than the record, "
              f"base.duration = {_show(duration)} s (the record repeats with that period)",
              "remove solver.t_end (the run ends with the record), or give a longer "
              "base.duration")
    levels = given.get("outputs.clearance")
    if levels is not None:
        if not 1 <= len(levels) <= MAX_LEVELS or not all(u > 0.0 for u in levels):
            _fail("scene key 'outputs.clearance'", f"{_show(list(levels))}: give 1 to "
                  f"{MAX_LEVELS} levels of |deflection|, each > 0 (m)",
                  "e.g. clearance = [0.001, 0.002]")
        if len(set(levels)) < len(levels):
            _fail("scene key 'outputs.clearance'", f"{_show(list(levels))}: a level is given "
                  "twice (the clearance coordinate's values must differ, for .sel)",
                  "remove the repeated level")
    _check_sampling(given, key)
    _check_spectra(given)


def _check_spectra(given: Mapping[str, Any]) -> None:
    """outputs.asd_resolution needs outputs.response_asd; the spectra's samples are the time
    series' (outputs.sample_interval is theirs, not the user's)."""
    if not given.get("outputs.response_asd"):
        if given.get("outputs.asd_resolution") is not None:
            _fail("scene key 'outputs.asd_resolution'", "only with outputs.response_asd = true",
                  "add response_asd = true to [outputs], or remove asd_resolution")
        return
    if given.get("outputs.sample_interval") is not None:
        _fail("scene key 'outputs.sample_interval'", "with outputs.response_asd the time series "
              "is sampled at the spectra's rate (4 x the spectrum's top frequency or more)",
              "remove outputs.sample_interval")


def _check_sampling(given: Mapping[str, Any], key: str) -> None:
    """The records' sample rate must carry the spectrum: at least MIN_RATE_FACTOR times its
    top frequency (sweep.models.random: the interpolant between samples, which the kernels
    integrate, loses more of the spectrum's top below it)."""
    from .random import DEFAULT_RATE_FACTOR, MIN_RATE_FACTOR
    top = float(given[key][-1][0])
    rate = given.get("base.sample_rate")
    if rate is not None and not rate >= MIN_RATE_FACTOR * top:
        _fail("scene key 'base.sample_rate'", f"{_show(rate)} Hz cannot carry the spectrum "
              f"up to {top:g} Hz (the records' interpolation between samples would lose "
              f"more than 5 % of it near its top)",
              f"give at least {MIN_RATE_FACTOR * top:g} Hz, or remove it (the default is "
              f"{DEFAULT_RATE_FACTOR:g} x, {DEFAULT_RATE_FACTOR * top:g} Hz)")


def defaults(values: dict[str, Any], mentioned: set[str]) -> None:
    """A random scene's defaults: its level 0 dB, one record, seed 0, the lanes driver (they
    take records: 1.9-2.6x the scalar driver's speed with several modes, about 1.8x with one,
    measured in benchmarks/RESULTS.md; rules.py keeps the scalar driver where too few points
    and records would fill them), DOP853 at rtol DEFAULT_RTOL, t_end
    the record's length, the statistics over the whole record after its start-up transient
    (metrics.tail 1), and no settling time or response period (they mean nothing for a random
    response)."""
    for dotted, value in (("base.asd_scale", 0.0), ("base.realisations", 1), ("base.seed", 0),
                          ("solver.driver", "lanes"), ("solver.method", "dop853"),
                          ("solver.rtol", DEFAULT_RTOL),
                          ("solver.t_end", values["base.duration"]), ("metrics.tail", 1.0),
                          ("outputs.settling_time", False),
                          ("outputs.response_period", False)):
        if dotted not in mentioned:
            values[dotted] = value


def sample_rate(values: Mapping[str, Any]) -> float:
    """The records' sample rate (Hz): base.sample_rate, or 10 x the spectrum's top
    frequency (the usual rule, docs/model.md sec. 11.1)."""
    given = values.get("base.sample_rate")
    return float(given) if given is not None else 10.0 * float(values[spectrum_key(values)][-1][0])


def ramp_time(values: Mapping[str, Any]) -> float:
    """base.ramp (s) of a scene's values: how long the records' level takes to rise from 0
    (0: none, the default)."""
    return float(values.get("base.ramp") or 0.0)


def transient_time(omega_1: Any, damping_ratio: Any, tolerance: Any, ramp: Any = 0.0) -> Any:
    """How long (s) a span's start-up takes: the records' level ramp (s, base.ramp), then its
    transient's decay to `tolerance` of its size, ln(1/tolerance) / (zeta w1), w1 (rad/s) its
    first mode's (mode 1 decays slowest: every mode's zeta w_n is w_n / w1 times mode 1's);
    infinite undamped. An overdamped mode (zeta > 1) decays by its slow root,
    w1 (zeta - sqrt(zeta^2 - 1)), not zeta w1. Element-wise: each row's statistics start
    after its own (sweep/models/modal.py's record block)."""
    zeta = damping_ratio
    over = np.sqrt(np.maximum(zeta * zeta - 1.0, 0.0))
    with np.errstate(divide="ignore"):
        return ramp + np.log(1.0 / tolerance) / ((zeta - over) * omega_1)


STARTUP_SHARE = 0.9
"""A point runs when its start-up ends before this share of the run (its statistics window
at least a tenth of it); one whose start-up lasts longer is flagged invalid_input, and a run
where no point runs is refused (`check_duration`)."""


def runs_after_startup(startup: Any, t_end: float) -> Any:
    """Whether a point whose start-up takes `startup` s (`transient_time`) runs in a run of
    t_end s (element-wise; STARTUP_SHARE)."""
    return startup < STARTUP_SHARE * t_end


CONFIDENCE_Z = 1.96
"""The normal quantile of a two-sided 95 % interval (base.rms_accuracy's confidence)."""


def warn_long_startups(t_end: float, startups: Any) -> None:
    """Warn (one line) where some points' start-up (`startups`, s, over the grid) outlasts
    STARTUP_SHARE of the run: they are flagged invalid_input, the others run."""
    import warnings

    from ..errors import CableSweepWarning
    starts = np.asarray(startups, float).ravel()
    long = ~runs_after_startup(starts, t_end)
    if not long.any() or long.all():
        return
    worst = float(np.max(starts))
    fix = (f"give base.duration of at least {_above(worst / STARTUP_SHARE)} s to run them too"
           if math.isfinite(worst) else "give them damping (cable.damping_ratio > 0)")
    warnings.warn(f"{int(long.sum())} of {starts.size} span settings start up for longer than "
                  f"{STARTUP_SHARE:.0%} of the {t_end:g} s run (up to {worst:.3g} s: "
                  "base.ramp plus ln(1/metrics.tolerance) / (zeta w1) of a long, lightly "
                  "damped span): their "
                  f"points are flagged invalid_input, the others run; {fix}",
                  CableSweepWarning, stacklevel=5)


def statistics_window(t_end: Any, tail: float, transient: Any) -> Any:
    """The length (s) of a point's statistics window: from the later of the tail window's
    start (the last `tail` of [0, t_end]) and the end of its start-up transient (s), to t_end
    (kernels.trajectory.delay_window)."""
    return t_end - np.maximum(t_end * (1.0 - tail), transient)


def rms_relative_error(omega_1: Any, damping_ratio: Any, window: Any, realisations: int) -> Any:
    """The relative standard error of the RMS response's mean over `realisations` records of
    `window` seconds each, of a span whose first mode (omega_1 rad/s, damping_ratio) carries the
    response: 1 / (2 sqrt(zeta w1 R T)) (docs/model.md sec. 11.3: a mean square from a record
    of T seconds errs by 1 / sqrt(zeta w1 T), the RMS by half of that). A hardening span's
    response is broader-band than the linear one's, so it errs less: the figure is an upper
    bound there (tests/test_random_accuracy.py checks it on a linear span)."""
    return 1.0 / (2.0 * np.sqrt(damping_ratio * omega_1 * realisations * window))


def required_realisations(accuracy: float, omega_1: Any, damping_ratio: Any,
                          window: Any) -> int:
    """The fewest realisations whose mean RMS has a 95 % half-width of at most `accuracy`
    (relative) at every point: CONFIDENCE_Z rms_relative_error <= accuracy."""
    need = (CONFIDENCE_Z / (2.0 * accuracy)) ** 2 / (damping_ratio * omega_1 * window)
    return int(np.max(np.ceil(np.asarray(need, float) - 1e-9)))


def _on_one_grid(natural_frequency: Any, damping_ratio: Any) -> tuple[np.ndarray, np.ndarray]:
    """(w1, zeta) (rad/s, 1) as arrays of one shape, point by point: DataArrays (a run's
    coefficients, each over the axes it varies on) broadcast by their dimensions, so a length
    axis and a damping axis make their product; plain arrays (the rules' aligned corners of
    the grid) by NumPy's rules."""
    import xarray as xr
    if isinstance(natural_frequency, xr.DataArray) or isinstance(damping_ratio, xr.DataArray):
        f1, zeta = xr.broadcast(xr.DataArray(natural_frequency), xr.DataArray(damping_ratio))
        natural_frequency, damping_ratio = f1.values, zeta.transpose(*f1.dims).values
    omega, zeta = np.broadcast_arrays(
        2.0 * math.pi * np.atleast_1d(np.asarray(natural_frequency, float)),
        np.atleast_1d(np.asarray(damping_ratio, float)))
    return omega, zeta


def check_accuracy(values: Mapping[str, Any], natural_frequency: Any,
                   damping_ratio: Any) -> None:
    """Refuse (one line) base.realisations too few for base.rms_accuracy at some point of
    the grid (natural_frequency: f1 in Hz, damping_ratio: at the grid's corners, where zeta w1
    and so the window and the error take their extremes). Points whose window is empty are
    left to `check_duration`."""
    accuracy = values.get("base.rms_accuracy")
    if accuracy is None:
        return
    omega, zeta = _on_one_grid(natural_frequency, damping_ratio)
    with np.errstate(divide="ignore", invalid="ignore"):
        window = statistics_window(float(values["solver.t_end"]),
                                   float(values["metrics.tail"]),
                                   transient_time(omega, zeta, float(values["metrics.tolerance"]),
                                                  ramp_time(values)))
        ok = (window > (1.0 - STARTUP_SHARE) * float(values["solver.t_end"]))
        ok &= np.isfinite(window) & (zeta > 0.0)
        if not ok.any():
            return
        omega, zeta, window = omega[ok], zeta[ok], window[ok]
        realisations = int(values["base.realisations"])
        half = CONFIDENCE_Z * rms_relative_error(omega, zeta, window, realisations)
    worst = int(np.argmax(half))
    if half[worst] <= accuracy:
        return
    need = required_realisations(accuracy, omega, zeta, window)
    _fail("scene key 'base.realisations'",
          f"{realisations} record{'s' if realisations != 1 else ''} of {window[worst]:.3g} s "
          f"after the start-up transient give{'s' if realisations == 1 else ''} the mean RMS "
          f"deflection to +-"
          f"{100.0 * half[worst]:.2g} % (95 %) at f1 = {omega[worst] / (2.0 * math.pi):.4g} "
          f"Hz, zeta = {zeta[worst]:g}, not the +-{100.0 * accuracy:g} % of "
          f"base.rms_accuracy = {_show(accuracy)}",
          f"give base.realisations = {need} or more, a longer base.duration or a looser "
          "base.rms_accuracy")


def check_spectra_samples(given: Mapping[str, Any], most: int) -> None:
    """With outputs.response_asd: refuse (one line) a run whose samples for the spectra
    (solver.t_end, or base.duration, at the spectra's rate) are more than `most` a point (the
    time series' limit, rules.MAX_SAMPLES)."""
    if not given.get("outputs.response_asd"):
        return
    rate = spectra_rate(given)
    t_end = float(given.get("solver.t_end") or given["base.duration"])
    if t_end * rate <= most:
        return
    _fail("scene key 'outputs.response_asd'", f"the spectra sample a run of {t_end:.6g} s at "
          f"{rate:g} Hz: {t_end * rate:.3g} samples a point, more than {most:,}",
          f"give base.duration of at most {most / rate:.6g} s, or remove response_asd")


def spectra_rate(values: Mapping[str, Any]) -> float:
    """The rate (Hz) the spectra sample the response at (outputs.response_asd,
    sweep/models/response_asd.py `asd_rate`), from a scene's values."""
    from .response_asd import asd_rate
    return asd_rate(sample_rate(values), float(values[spectrum_key(values)][-1][0]))


def shortest_window(t_end: float, tail: float, tolerance: float, natural_frequency: Any,
                    damping_ratio: Any, ramp: float = 0.0) -> float:
    """The shortest statistics window (s, `statistics_window`) over the points of a run of
    t_end s (tail: metrics.tail; tolerance: metrics.tolerance, for the start-up transient):
    natural_frequency f1 (Hz) and damping_ratio on the grid, or at its corners, where zeta w1
    takes its extremes."""
    omega, zeta = _on_one_grid(natural_frequency, damping_ratio)
    with np.errstate(divide="ignore", invalid="ignore"):
        start = transient_time(omega, zeta, tolerance, ramp)
        window = statistics_window(t_end, tail, start)
    running = window[runs_after_startup(start, t_end)]    # the others are invalid_input
    if running.size:
        return float(np.min(running))
    return float(np.min(window)) if window.size else 0.0


def check_spectra_window(values: Mapping[str, Any], natural_frequency: Any,
                         damping_ratio: Any) -> None:
    """With outputs.response_asd: refuse (one line) a grid whose shortest statistics window
    holds no Welch segment at the asked resolution (sweep/models/response_asd.py)."""
    if not values.get("outputs.response_asd"):
        return
    from .response_asd import segment_length
    t_end = float(values["solver.t_end"])
    window = shortest_window(t_end, float(values["metrics.tail"]),
                             float(values["metrics.tolerance"]), natural_frequency,
                             damping_ratio, ramp_time(values))
    if not window > 0.1 * t_end:
        return                  # a run too short for the start-up: check_duration's refusal
    segment_length(window, spectra_rate(values), values.get("outputs.asd_resolution"))


def _above(threshold: float) -> str:
    """`threshold` (s) rounded up to 3 significant digits and past it, as advice: a duration
    read off the line then passes the strict test (`runs_after_startup`)."""
    if not (math.isfinite(threshold) and threshold > 0.0):
        return f"{threshold:.3g}"
    step = 10.0 ** (math.floor(math.log10(threshold)) - 2)
    value = (math.floor(threshold / step) + 1) * step
    return f"{value:.3g}"


def check_duration(t_end: float, startup: float, ramp: float = 0.0) -> None:
    """Refuse (one line) a run that leaves less than a tenth of itself after the start-up
    of its best-damped point (`startup`, s: the shortest over the grid), so that no point has
    a statistics window: each point's statistics start after its own transient
    (kernels.trajectory.delay_window), and a point whose own start-up is too long is flagged
    invalid_input (`warn_long_startups`)."""
    if not math.isfinite(startup):
        _fail("scene key 'cable.damping_ratio'", "a random response needs damping: without it "
              "the start-up transient never decays and the response has no stationary "
              "statistics", "give a damping ratio above 0, e.g. 0.02")
    if not runs_after_startup(startup, t_end):
        _fail("scene key 'base.duration'", f"the run ({t_end:g} s) leaves less than a tenth "
              f"of it after the start-up transient has decayed ({startup:.3g} s = "
              + (f"base.ramp {ramp:g} s + " if ramp > 0.0 else "")
              + "ln(1/metrics.tolerance) / (zeta w1) at the best-damped point)",
              f"give base.duration of at least {_above(startup / STARTUP_SHARE)} s (the "
              f"statistics then start after the transient; {_above(10.0 * startup)} s keeps 90 % "
              "of the record for them), or more damping")
