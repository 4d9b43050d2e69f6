"""Base excitation of the clamps as the kernels take it (kernels.excitation's block of
columns): a fixed frequency or a logarithmic sine sweep, a constant level or a table of
(frequency, level) breakpoints interpolated log-log (docs/model.md secs. 5 and 6).

A sweep from f_s to f_e (Hz) at r octaves per minute (down when f_e < f_s) has

    lam = s r ln 2 / 60 (1/s), s = sign(ln(f_e / f_s)),   f(t) = f_s exp(lam t),
    T = 60 |log2(f_e / f_s)| / r (s),   phi(t) = 2 pi f_s (exp(lam t) - 1) / lam.

Every function works element-wise on floats, NumPy arrays or xarray DataArrays.
"""

from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from ..schema import STANDARD_GRAVITY
from .swept import Swept

EXCITATION_NAMES: tuple[str, ...] = (
    ("base_accel", "base_omega", "base_phase", "sweep_rate", "level_segments", "sweep_end",
     "log_base_omega") + tuple(f"level_{what}_{k}" for what in ("edge", "log", "slope")
                               for k in range(8)) + ("level_ramp",))
"""kernels.excitation.NAMES, written here so that the models need not import Numba (a test
checks that the two agree)."""

MAX_BREAKPOINTS = 9
"""Most breakpoints of a level table (kernels.excitation.MAX_SEGMENTS + 1)."""


def sweep_rate(start: Any, stop: Any, rate: Any) -> Any:
    """lam (1/s) of a logarithmic sweep from start to stop (Hz) at rate octaves per minute:
    f(t) = start exp(lam t); negative for a down sweep."""
    return np.sign(np.log(stop / start)) * rate * math.log(2.0) / 60.0


def sweep_duration(start: Any, stop: Any, rate: Any) -> Any:
    """T (s): how long a sweep from start to stop (Hz) at rate (octaves per minute) takes,
    60 |log2(stop / start)| / rate."""
    return 60.0 * np.abs(np.log2(stop / start)) / rate


def sweep_frequency(t: Any, start: Any, stop: Any, rate: Any) -> Any:
    """f(t) (Hz), the excitation frequency of the sweep at time t (s)."""
    return start * np.exp(sweep_rate(start, stop, rate) * t)


DEFAULT_RAMP_CYCLES = 10.0
"""base.sweep.ramp_cycles of a scene that gives none: the level rises over 10 cycles of the
sweep's start frequency (0.1 s at 100 Hz, 2 s at 5 Hz), as a shaker ramps its level up."""


def ramp_time(start: Any, cycles: Any) -> Any:
    """The level's rise time (s) at the start of a sweep from `start` (Hz): `cycles` cycles of
    the start frequency (docs/model.md sec. 6)."""
    return cycles / start


def sweep_phase(t: Any, start: Any, stop: Any, rate: Any) -> Any:
    """phi(t) (rad) of the sweep at time t (s): 2 pi f_s (exp(lam t) - 1) / lam."""
    lam = sweep_rate(start, stop, rate)
    return 2.0 * np.pi * start * np.expm1(lam * t) / lam


def table_level(levels_g: Sequence[Sequence[float]], frequency: Any) -> Any:
    """The level (m/s^2 peak) of a table of (Hz, g) breakpoints at `frequency` (Hz),
    interpolated log-log between breakpoints (a constant level, or a slope in dB/octave)."""
    f = np.array([b[0] for b in levels_g], float)
    g = np.array([b[1] for b in levels_g], float)
    values = np.exp(np.interp(np.log(np.asarray(frequency, float)), np.log(f), np.log(g)))
    if hasattr(frequency, "copy") and hasattr(frequency, "dims"):
        return frequency.copy(data=values * STANDARD_GRAVITY)
    return (values * STANDARD_GRAVITY)[()]


def block(accel: Any, omega: Any, rate: Any = 0.0, end: Any = math.inf,
          levels_g: Sequence[Sequence[float]] | None = None, ramp: Any = 0.0) -> dict[str, Any]:
    """kernels.excitation's columns by name (its NAMES): constant level accel (m/s^2) or, with
    a sweep and a table, the table's segments; omega the (start) angular frequency (rad/s);
    rate lam (1/s, 0: fixed frequency); end: the sweep's end (s, after which a_b = 0); ramp:
    a sweep's level rise time (s, `ramp_time`; 0: full level from t = 0).

    A table with a fixed frequency is read here (accel = its level there); along a sweep the
    kernel reads it (segments in ln w: edges ln(2 pi f_k), ln A_k, log-log slopes)."""
    out: dict[str, Any] = {"base_accel": accel, "base_omega": omega, "base_phase": 0.0,
                           "sweep_rate": rate, "level_segments": 0.0, "sweep_end": 0.0,
                           "log_base_omega": 0.0}
    for k in range(MAX_BREAKPOINTS - 1):
        out[f"level_edge_{k}"] = out[f"level_log_{k}"] = out[f"level_slope_{k}"] = 0.0
    out["level_ramp"] = 0.0
    if not np.any(np.asarray(rate) != 0.0):
        return out
    out["level_ramp"] = ramp
    if levels_g is None:                  # one segment of slope 0: the level ends with the sweep
        with np.errstate(divide="ignore"):
            out.update(level_segments=1.0, sweep_end=end, log_base_omega=np.log(omega),
                       level_log_0=np.log(accel))
        return out
    f = np.array([b[0] for b in levels_g], float)
    log_a = np.log(np.array([b[1] for b in levels_g], float) * STANDARD_GRAVITY)
    log_w = np.log(2.0 * np.pi * f)
    out.update(level_segments=float(f.size - 1), sweep_end=end, log_base_omega=np.log(omega))
    for k in range(f.size - 1):
        out[f"level_edge_{k}"] = log_w[k]
        out[f"level_log_{k}"] = log_a[k]
        out[f"level_slope_{k}"] = (log_a[k + 1] - log_a[k]) / (log_w[k + 1] - log_w[k])
    return out


SWEEP_KEYS: tuple[str, str, str] = ("base.sweep.start", "base.sweep.stop", "base.sweep.rate")
"""The keys of a logarithmic sweep ([base] sweep = {start, stop, rate})."""
SWEEP_AXES: tuple[str, str, str] = ("base_sweep_start", "base_sweep_stop", "base_sweep_rate")
SWEEP_DIRECTION = "base.sweep.direction"
"""Optional: up, down or both ways between start and stop (default: from start to stop)."""


def is_swept(values: Mapping[str, Any], axes: Mapping[str, Any]) -> bool:
    """Whether a scene's base frequency is swept (any base.sweep key, as a key or an axis)."""
    return any(values.get(d) is not None for d in SWEEP_KEYS) or any(a in axes
                                                                      for a in SWEEP_AXES)


def sweep_grid(values: Mapping[str, Any], axes: Mapping[str, Any]) -> tuple[Any, Any, Any]:
    """(start, stop, rate) of a swept scene over the combinations it solves (arrays that
    broadcast): the product of its sweep axes, [points] zipped on one dimension (`axes` a
    `Swept`; a plain mapping is all axes); scalars where not swept."""
    swept = Swept.of(axes)
    fixed = {a: values[d] for d, a in zip(SWEEP_KEYS, SWEEP_AXES)}
    shaped = swept.product(SWEEP_AXES, fixed)
    return shaped[0], shaped[1], shaped[2]


def longest_sweep(values: Mapping[str, Any], axes: Mapping[str, Any]) -> float:
    """The longest sweep duration (s) of a swept scene's points."""
    return float(np.max(sweep_duration(*sweep_grid(values, axes))))


def end_time(values: Mapping[str, Any], axes: Mapping[str, Any]) -> float:
    """The run's end time (s): solver.t_end, or for a swept scene that gives none, its
    longest sweep (each point then ends with its own sweep)."""
    t_end = values["solver.t_end"]
    return float(t_end) if t_end is not None else longest_sweep(values, axes)


BAND_REFERENCE = 1000.0
"""Hz: the centre of band 0 of the base-2 fractional-octave bands, 1000 x 2^(k/N) Hz."""


def band_index(frequency: Any, bands_per_octave: int) -> Any:
    """k of the base-2 1/N-octave band that holds `frequency` (Hz): round(N log2(f / 1000)),
    as kernels.metrics.sweep_metrics computes it."""
    return np.floor(bands_per_octave * np.log2(np.asarray(frequency, float) / BAND_REFERENCE)
                    + 0.5).astype(int)[()]


def band_centres(first: int, count: int, bands_per_octave: int) -> np.ndarray:
    """Centre frequencies (Hz) of bands first .. first + count - 1: 1000 x 2^(k/N)."""
    return BAND_REFERENCE * 2.0 ** (np.arange(first, first + count) / bands_per_octave)


def band_bounds(first: int, count: int, bands_per_octave: int) -> np.ndarray:
    """(count, 2) lower and upper edges (Hz) of those bands: the centre / and x 2^(1/2N)."""
    centres = band_centres(first, count, bands_per_octave)
    half = 2.0 ** (0.5 / bands_per_octave)
    return np.stack([centres / half, centres * half], axis=1)
