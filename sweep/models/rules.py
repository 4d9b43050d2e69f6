"""The scene rules that are physics: which keys and axes each model kind takes, its defaults,
and the checks of a resolved scene. The scene pipeline (sweep/scene/build.py) checks every key
against the schema, then calls `check_base`, the kind's `Rules.check`, `check_pairs`, the
kind's `Rules.defaults` and `Rules.check_resolved` (`RULES`, through
`sweep.models.rules_for`). Every refusal is one SceneError line, worded as the scene's own
(sweep/scene/messages.py).

Shared rules:
- ``load.frequency`` and ``load.frequency_ratio`` are alternatives; if neither is given,
  ``load.frequency_ratio = 1.0``. Both keys of an either-or pair (PAIRS), as scalars or axes,
  are refused.
- ``solver.courant`` above 1 is refused whatever the model (the scheme is unstable there).
- ``cable.inertia`` not given: `default_inertia` of the area, the bending moment of a solid
  round section, A^2 / (4 pi). With ``area`` swept, ``values["cable.inertia"]`` is None and the
  inertia follows the area point by point (`sweep.grid.parameters`).
- The derived coefficients (`sweep.models.oscillator`, `sweep.models.wave.wave_parameters`)
  must be finite at every corner of the grid.
- The cable is given by material (youngs_modulus, density, area, inertia) or by its data
  sheet (linear_mass, bending_rigidity or f1_measured, axial_rigidity, diameter; or a wire of
  sweep/wires.py), never both: sweep/models/cable.py holds those rules (`cable.check`, called
  by the scene pipeline after the kind's) and turns a data sheet into the material the
  formulas here and in the models take (`cable.resolve`).

Transverse scenes (``model.kind = "transverse"``, the default):
- ``solver.t_end`` defaults to 5.0 s; ``solver.transits`` is refused.
- ``outputs.sample_interval``, ``solver.max_step`` and ``solver.first_step`` must be
  <= ``solver.t_end``; with ``outputs.time_series``, t_end / sample_interval must be
  <= MAX_SAMPLES (10 million samples per point). ``solver.min_step`` must be <= t_end and
  <= ``solver.max_step``.
- With ``model.coefficients = "paper"`` the cable data is baked into Eq.32, so its
  parameters cannot be swept, a cable key (and ``model.membrane``) other than Table 1's value
  is refused (it would be ignored), and ``initial.velocity`` defaults to 0.0321 m/s when no
  initial condition is given (docs/model.md: that reproduces the paper's Fig 5 amplitudes).
- ``model.modes`` above 1 (docs/model.md sec. 7) needs ``model.coefficients = "consistent"``
  (Eq.32 is one mode's). ``initial.modal_displacement`` and ``initial.modal_velocity`` have one
  entry per mode and replace ``initial.displacement`` / ``initial.velocity`` (mode 1's alone):
  both spellings of one, as keys or axes, are refused.
- Every point starting at q = q' = 0 (an empty scene, for one) gives q = 0 everywhere (the
  end load only changes the stiffness): load_scene warns (CableSweepWarning) and runs it,
  unless base excitation of a non-zero level drives the span.

Base excitation (``[base]``, docs/model.md sec. 5; `has_base`):
- A ``[base]`` table or a base axis (``base_acceleration``, ``base_acceleration_g``,
  ``base_frequency``, ``base_frequency_ratio``; an axis counts as the table's key, as the load
  axes do) needs a level, ``base.acceleration`` (m/s^2) or ``base.acceleration_g`` (g), and a
  frequency, ``base.frequency`` (Hz) or ``base.frequency_ratio`` (f/f1), each as a key or an
  axis, and one spelling of each only. No defaults: a scene without them has no base motion.
- Refused with ``model.kind = "longitudinal"`` and with ``model.coefficients = "paper"``
  (Eq.32 as printed has no forcing term).

Longitudinal scenes (``model.kind = "longitudinal"``, docs/model.md sec. 4):
- ``load.type`` defaults to "constant", the only type allowed (a suddenly applied end load).
- Only ``length``, ``load_amplitude``, ``youngs_modulus``, ``density`` and ``area`` can be
  swept.
- The end time is ``solver.t_end`` (s) or ``solver.transits`` (multiples of l/a), not both;
  with neither, ``solver.transits = 8.0``. Exactly one of the two values is not None.
- With ``solver.t_end`` given, every ``outputs.snapshot_times`` entry must be <= it; with
  transits the end time depends on the point, and an entry must be <= the longest one
  (transits x max over the grid of l sqrt(rho/E); shorter spans give NaN snapshots there),
  and with ``outputs.histories`` t_end / sample_interval must be <= MAX_SAMPLES.
- The most time levels a span needs, t_end / dt with dt = courant (l / intervals) / a over
  the grid, must be <= LEVEL_LIMIT (2^62); more than ``solver.max_steps`` runs max_steps
  levels and is flagged max_steps_reached.
- Transverse-only keys (tolerances, coefficients, frequencies, ``[initial]``, ``[metrics]``,
  the time-series outputs, ...) are accepted and ignored, so a resolved scene written by
  `Scene.to_toml` loads back; the transverse time checks above are not applied.

This module imports no model (no runner, no kernels beyond a plain constant) and no part of
the scene pipeline but its messages.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .excitation import SWEEP_DIRECTION, SWEEP_KEYS, end_time, sweep_duration, sweep_grid
from .swept import Swept

from sweep.kernels.wave_layout import LEVEL_LIMIT  # most time levels a span counts

from .. import schema
from ..errors import CableSweepWarning
from ..scene.messages import _fail, _show
from . import cable, random_scene
from .modal import load_from_ratio, oscillator
from .wave import wave_parameters

PAPER_VELOCITY = 0.0321
"""initial.velocity (m/s) used by the paper preset when no initial condition is given."""


def default_inertia(area: Any) -> Any:
    """cable.inertia (m^4) of a scene that gives none: the bending second moment of area of a
    solid round section of ``area`` (m^2), pi d^4 / 64 = A^2 / (4 pi); 2.865e-12 for 6e-6.

    Element-wise on floats, arrays and DataArrays. The paper's 5.73e-12 is the polar moment
    of its 6 mm^2 section (twice this), and a stranded cable bends more easily than a solid
    one: give a measured inertia (EI / E) for it (see the cable.inertia key in README.md).
    """
    return area * area / (4.0 * math.pi)


PAPER_FIXED_AXES: tuple[str, ...] = ("youngs_modulus", "density", "area", "inertia", "membrane")
"""Axes the paper preset cannot sweep: Eq.32 has these numbers baked in."""
PAPER_CABLE: dict[str, tuple[float, ...]] = {
    "cable.youngs_modulus": (1.1e11,), "cable.density": (8900.0,), "cable.area": (6e-6,),
    # Table 1's I, and the default A^2/(4 pi) of its area (what Scene.to_toml writes)
    "cable.inertia": (5.73e-12, 6e-6 * 6e-6 / (4.0 * math.pi)), "model.membrane": (0.375,)}
"""The cable data Eq.32 was derived from (Table 1, docs/model.md sec. 1): under
``model.coefficients = "paper"`` a scalar key may only repeat one of these values."""

LOAD_KEYS: tuple[str, str] = ("load.amplitude", "load.amplitude_ratio")
FREQUENCY_KEYS: tuple[str, str] = ("load.frequency", "load.frequency_ratio")
DEFAULT_FREQUENCY_RATIO = 1.0
"""load.frequency_ratio of a scene that gives neither load frequency key."""

BASE_LEVEL_KEYS: tuple[str, str] = ("base.acceleration", "base.acceleration_g")
BASE_FREQUENCY_KEYS: tuple[str, str] = ("base.frequency", "base.frequency_ratio")
BASE_TABLE_KEY = "base.levels_g"
BASE_KEYS: tuple[str, ...] = (BASE_LEVEL_KEYS + (BASE_TABLE_KEY,) + BASE_FREQUENCY_KEYS
                              + SWEEP_KEYS)
BASE_FIX = ("add a [base] table with acceleration, acceleration_g or levels_g and frequency, "
            "frequency_ratio or sweep")
"""How to fix a base key or axis given without the rest of the base excitation."""
PAIRS: tuple[tuple[str, str], ...] = (LOAD_KEYS, FREQUENCY_KEYS, BASE_LEVEL_KEYS,
                                      BASE_FREQUENCY_KEYS)
"""Either-or keys: two spellings of one quantity (as scalars or axes), never both."""
_PAIR_UNITS: dict[str, str] = {
    "load.amplitude": "amplitude is in N, amplitude_ratio in multiples of the span's buckling "
                      "load",
    "load.frequency": "load.frequency is in Hz, load.frequency_ratio in multiples of w1",
    "base.acceleration": "acceleration is in m/s^2, acceleration_g in g = "
                         f"{schema.STANDARD_GRAVITY:g} m/s^2",
    "base.frequency": "frequency is in Hz, frequency_ratio in multiples of f1 of the unloaded "
                      "span"}

END_TIME_KEYS: tuple[str, str] = ("solver.t_end", "solver.transits")
DEFAULT_T_END = 5.0
"""solver.t_end (s) of a transverse scene that gives none."""
DEFAULT_TRANSITS = 8.0
"""solver.transits of a longitudinal scene that gives neither solver.t_end nor transits."""

LANES_LEAST_POINTS = 4
"""Points that share one lanes call, at least, for a scene of several modes to run on the
lock-step lanes by default; with fewer (a single span; elastic clamps of 5 modes or more, whose
K = k_t l / EI differs at every point, each K its own basis and so its own kernel call) the
scalar driver is the default. Elastic clamps of up to 4 modes count every point: their bases
stack into one call (`family_shares_lanes`; harness-clamps' 35 spans, 35 bases: 0.55x the
scalar driver's time on one thread, 0.81x on two, thirtieth session, benchmarks/RESULTS.md).
A stepped sweep counts its lines (a kernel call takes one dwell of every line of a
direction). Measured (benchmarks/lanes_occupancy.py,
2026-12-06, thirtieth session, once the lanes' right-hand side was inlined): the lanes took
1.36x the scalar driver's time with 1 point a basis, 0.75x with 4, 0.56x with 8, 0.42x with 16
(their vector loops and per-step bookkeeping cost nearly as much for one running lane as for
sixteen; 1.39x, 0.90x, 0.59x and 0.45x the session before; 3.4x, 1.0x, 0.70x and 0.52x on
2026-12-04, before the scalar step lost its counts); harness-stepped-sine's 3 lines a
direction, one thread: 3.6 s on the lanes, 2.7 s on the scalar driver (`python
benchmarks/thread_scaling.py harness-stepped-sine [--set 'solver.driver="lanes"']`, thirtieth
session; 4.2 s and 2.9 s the session before, 5.0 s and 4.1 s before that)."""
RANDOM_LANES_LEAST_POINTS = 4
"""The same for a random scene, counting each record (base.realisations) as a point. Measured
(3 modes, one 100 mm span at -10 dB, 2 s GEVS records, one thread, 2026-12-06, once a record's
ordinary steps stayed in the lanes; benchmarks/random_lanes.py --occupancy for pinned ends):
the lanes took 1.7-2.2x the scalar driver's time with 2 records a basis, 0.81x (pinned), 0.87x
(clamped) and 0.88x (elastic, K = 1) with 4, 0.55-0.73x with 8. (8 until then, when every
step of a record went to the lanes' scalar path: 1.23x with 4, 0.77x with 8.) Measured again
once the scalar step lost its reference counts (twenty-ninth session, pinned): 4.96x with 1
record, 2.70x with 2, 1.04x with 4, 0.73x with 8, 0.55x with 16."""
RANDOM_ONE_MODE_LANES_LEAST_POINTS = 2
"""The same for a random scene of one mode (no basis: one kernel call takes every point),
counting each record as a point. Measured (benchmarks/random_lanes.py --one-mode, GEVS at
-10 dB on a 100 mm span, 2 s records, one thread): the lanes took 1.34x the scalar driver's
time with 1 record, 0.99x with 2, 0.63x with 4, 0.55x with 8."""
BASIS_KEYS_EXEMPT = frozenset({"cable.damping_ratio", "cable.density", "cable.linear_mass"})
"""cable.* keys that do not move K = k_t l / EI (every other cable key may: the length and
the cable's bending rigidity, however it is given)."""

MULTI_MODE_METHOD = "dop853"
"""solver.method of a scene with model.modes >= 2 that gives none. Measured on the multi-mode
built-in scenes' samples (benchmarks/workloads.py, benchmarks/RESULTS.md): at the default rtol
1e-8 DOP853 runs harness-base-sine 1.75x, harness-clamps 2.0x and harness-stepped-sine 2.4x
faster than RK45, its headline output within 2e-9 of the rtol 1e-12 reference on each (RK45:
within 9e-9). A one-mode scene keeps RK45 (solver.method's default; DOP853 gains 1.1-1.4x
there, `solver.method = "dop853"`)."""

SWEEP_MAX_STEPS = 20_000_000
"""solver.max_steps of a swept scene that gives none: a 130 s sweep to 100 Hz takes up to ~1e6
RK45 steps at rtol = 1e-8 (about 50 per cycle of a short span's f1), 10x that at 1e-10."""

LONGITUDINAL_AXES: tuple[str, ...] = ("length", "load_amplitude", "youngs_modulus", "density",
                                      "area")
"""The axes a longitudinal scene can sweep (the parameters of the wave problem)."""
LONGITUDINAL_LOAD = "constant"
"""load.type of a longitudinal scene, the only one it takes (a suddenly applied end load)."""

MAX_SAMPLES = 10_000_000
"""Most time-series samples per point (solver.t_end / outputs.sample_interval)."""


def has_base(values: Mapping[str, Any], axes: Mapping[str, Any]) -> bool:
    """Whether a resolved scene (its values and axes) has base excitation: a base level is
    given, as a [base] key or an axis (a validated scene then has a base frequency too)."""
    return values.get(BASE_TABLE_KEY) is not None or random_scene.is_random(values) or any(
        values.get(d) is not None or schema.BY_DOTTED[d].axis in axes for d in BASE_LEVEL_KEYS)


def model_kind(given: Mapping[str, Any]) -> str:
    """The model.kind of a scene's given keys (dotted key -> value): given, else the default."""
    return given.get("model.kind", schema.BY_DOTTED["model.kind"].default)


def check_value(where: str, dotted: str, value: Any) -> None:
    """Refuse one key's value that the physics rules out whatever the model, beyond the
    schema's bounds: ``solver.courant`` (dimensionless) above 1, where the central difference
    is unstable. `where` names the key in the message."""
    if dotted == "solver.courant" and value > 1.0:
        _fail(where, f"must be <= 1, got {_show(value)}", _courant_fix(value))


def _courant_fix(courant: float) -> str:
    """Why a Courant number above 1 is refused, with the growth per step of the worst mode.

    The grid-scale mode (k dx = pi) of the three-level central difference has amplification
    factors g with g^2 - b g + 1 = 0, b = 2 - 4 C^2; for C > 1, |g| = |b|/2 + sqrt(b^2/4 - 1).
    """
    half_b = abs(2.0 - 4.0 * courant * courant) / 2.0
    growth = half_b + math.sqrt(max(half_b * half_b - 1.0, 0.0))
    if not math.isfinite(growth):
        rate = "beyond any bound"
    elif growth >= 1000.0:
        rate = f"about {growth:.3g}x per step"
    elif growth - 1.0 >= 0.01:
        rate = f"about {growth:.2f}x per step"
    elif growth > 1.0:
        rate = f"about {growth:.{min(12, 1 - math.floor(math.log10(growth - 1.0)))}f}x per step"
    else:
        rate = "slowly"
    return ("the explicit central difference is unstable above 1: its grid-scale mode grows "
            f"{rate} at C = {_show(courant)}; use 1.0, which is exact at the nodes")


def check_base(given: dict[str, Any], axes: dict[str, np.ndarray], has_table: bool,
               file_has_base: bool) -> None:
    """Rules of base excitation (docs/model.md sec. 5): a [base] table or base axis needs a
    level and a frequency (each as a key or an axis), a transverse scene and the consistent
    coefficients. given: dotted key -> value; axes: axis name -> values; `has_table`: the
    document (overrides applied) has a [base] table; `file_has_base`: the scene file itself
    (before overrides) has one; if not (a lone base axis, an override), the fix says to add
    the table."""
    named = [(f"axis '{schema.BY_DOTTED[d].axis}'" if schema.BY_DOTTED[d].axis in axes
              else f"scene key '{d}'")
             for d in BASE_KEYS if _present(d, given, axes)]
    _check_envelope(given, axes)
    random_scene.check(given, axes)
    if random_scene.is_random(given):
        random_scene.check_spectra_samples(given, MAX_SAMPLES)
        return                          # a spectrum instead of a level and a frequency
    if not named and not has_table:
        return
    where = named[0] if named else "scene section '[base]'"
    if model_kind(given) == "longitudinal":
        _fail(where, "model.kind = 'longitudinal' has no base excitation (the clamps' "
              "transverse motion drives the transverse modal equation only)",
              "remove the [base] table and the base axes, or use model.kind = 'transverse'")
    if given.get("model.coefficients") == "paper":
        _fail(where, "model.coefficients = 'paper' has no base excitation (Eq.32 as printed "
              "has no forcing term)", "use model.coefficients = 'consistent'")
    for pair, what, example in ((BASE_LEVEL_KEYS + (BASE_TABLE_KEY,), "a level",
                                 "acceleration_g = 0.5 (g), acceleration = 4.9 (m/s^2) or "
                                 "levels_g = [[5.0, 0.5], [100.0, 0.6]] (Hz, g)"),
                                (BASE_FREQUENCY_KEYS + SWEEP_KEYS, "a frequency",
                                 "frequency = 20.0 (Hz), frequency_ratio = 1.0 (f/f1) or "
                                 "sweep = { start = 5.0, stop = 100.0, rate = 2.0 }")):
        if any(_present(d, given, axes) for d in pair):
            continue
        _fail(where, f"base excitation needs {what}: the scene gives none of "
              f"{', '.join(dict.fromkeys(_spelling(d) for d in pair))} (as a key or axis)",
              BASE_FIX if not file_has_base else f"add {example} to the [base] table")
    _check_sweep(given, axes)


def _check_envelope(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """The envelope outputs need a sweep, and its bands an envelope, whatever the scene."""
    if not given.get("outputs.envelope"):
        _refuse_without(given, ("outputs.bands_per_octave",), "sets the envelope's bands, but "
                        "the scene asks for no envelope", "add outputs.envelope = true (a sweep's "
                        "response envelope), or remove the key")
    elif not any(_present(d, given, axes) for d in SWEEP_KEYS):
        _fail("scene key 'outputs.envelope'", "needs a swept base frequency (the envelope is "
              "read against the sweep's frequency)", "add [base] sweep = { start = 5.0, stop "
              "= 100.0, rate = 2.0 }, or remove the key")


def _spelling(dotted: str) -> str:
    """A base key as a scene writes it: base.sweep for its three keys."""
    return "base.sweep" if dotted in SWEEP_KEYS else dotted


def _present(dotted: str, given: dict[str, Any], axes: dict[str, np.ndarray]) -> bool:
    """Whether the scene gives key `dotted`, as a key or as its axis."""
    axis = schema.BY_DOTTED[dotted].axis
    return dotted in given or (axis is not None and axis in axes)


def _check_sweep(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules of a sine sweep and a level table (docs/model.md sec. 6): a sweep has a start, a
    stop and a rate (keys or axes) that differ, replaces base.frequency and
    base.frequency_ratio, of several modes is solved by the scalar driver, has no settling
    time and is not a stepped sweep; a level table replaces the constant level and covers
    every frequency the scene's sweeps reach; the envelope outputs need a sweep."""
    swept = [d for d in SWEEP_KEYS if _present(d, given, axes)]
    table = given.get(BASE_TABLE_KEY)
    if table is not None:
        for dotted in BASE_LEVEL_KEYS:
            if _present(dotted, given, axes):
                _fail(f"scene keys '{dotted}' and '{BASE_TABLE_KEY}'", "give one level, not "
                      "both (a constant level, or a table of breakpoints)",
                      f"remove one of them: {_PAIR_UNITS['base.acceleration']}")
    if not swept and given.get("base.sweep.ramp_cycles") is not None:
        _fail("scene key 'base.sweep.ramp_cycles'", "needs a sweep (start, stop and rate): a "
              "fixed frequency starts at full level", "write sweep = { start = 5.0, stop = "
              "100.0, rate = 2.0, ramp_cycles = 10.0 }, or remove the key")
    if not swept and given.get(SWEEP_DIRECTION) is not None:
        _fail(f"scene key '{SWEEP_DIRECTION}'", "needs a sweep (start, stop and rate)",
              "write sweep = { start = 5.0, stop = 100.0, rate = 2.0, direction = 'both' }")
    if not swept:
        return
    where = "scene key 'base.sweep'"
    missing = [d.rpartition(".")[2] for d in SWEEP_KEYS if d not in swept]
    if missing:
        _fail(where, f"needs start, stop and rate; missing {', '.join(missing)}",
              "write sweep = { start = 5.0, stop = 100.0, rate = 2.0 } (Hz, Hz, octaves per "
              "minute; as keys or axes base_sweep_start, base_sweep_stop, base_sweep_rate)")
    for dotted in BASE_FREQUENCY_KEYS:
        if _present(dotted, given, axes):
            _fail(f"scene keys '{dotted}' and 'base.sweep'", "give one frequency, not both (a "
                  "fixed frequency, or a sweep)", f"remove {dotted} or the sweep")
    values = {d: given.get(d) for d in SWEEP_KEYS}
    start, stop, rate = sweep_grid(values, axes)
    if np.any(start == stop):
        _fail(where, "start and stop are equal at some point: nothing to sweep",
              "give different start and stop frequencies (stop below start sweeps down), or "
              "use base.frequency for a fixed frequency")
    _check_sweep_extent(given, start, stop, rate)
    if table is not None:
        low, high = table[0][0], table[-1][0]
        f_lo, f_hi = float(np.min(np.minimum(start, stop))), float(np.max(np.maximum(start, stop)))
        if f_lo < low * (1 - 1e-12) or f_hi > high * (1 + 1e-12):
            _fail(f"scene key '{BASE_TABLE_KEY}'", f"covers {low:g} to {high:g} Hz, but the "
                  f"sweep reaches {f_lo:g} to {f_hi:g} Hz", "extend the table to every "
                  "frequency the sweep reaches, or narrow the sweep")
    if given.get("continuation.axis") is not None:
        _fail("scene key 'continuation.axis'", "a continuous sweep ([base] sweep) carries its "
              "state and phase itself; [continuation] steps a fixed frequency",
              "remove [continuation], or use base.frequency with a frequency axis for a "
              "stepped sweep")
    if given.get("solver.driver") == "lanes" and given.get("model.modes", 1) > 1:
        _fail("scene key 'solver.driver'", "a swept base frequency of several modes is solved "
              "by the 'scalar' driver only (the lanes take a sweep of one mode)",
              "remove solver.driver (a sweep of several modes takes 'scalar')")
    if given.get("outputs.settling_time"):
        _fail("scene key 'outputs.settling_time'", "a sweep has no settling time (its "
              "excitation never stops changing)", "remove it: a swept scene stores "
              "peak_amplitude, peak_frequency and, with outputs.envelope = true, the envelope")


MIN_SWEEP_CYCLES = 10.0
"""Fewest excitation cycles a sweep may pass through: fewer is a transient, not a sweep."""
MAX_SWEEP_DURATION = 1e7
"""Longest sweep (s, about 4 months): beyond it a sweep is a fixed frequency to any step."""


def _check_sweep_extent(given: dict[str, Any], start: Any, stop: Any, rate: Any) -> None:
    """Refuse what cannot be a sweep: one that passes fewer than MIN_SWEEP_CYCLES cycles of
    its excitation (|stop - start| / lam, lam = rate ln2 / 60: a rate of 1e300 oct/min, or a
    one-ulp sweep) or lasts longer than MAX_SWEEP_DURATION (a rate of 5e-324 oct/min), and a
    solver.t_end that would cut a sweep short (each point's run ends with its own sweep when
    t_end is not given)."""
    where = "scene key 'base.sweep'"
    with np.errstate(all="ignore"):
        start, stop, rate = np.broadcast_arrays(*(np.asarray(x, np.float64)
                                                  for x in (start, stop, rate)))
        duration = sweep_duration(start, stop, rate)
        cycles = np.abs(stop - start) / (rate * math.log(2.0) / 60.0)

    def which(bad: np.ndarray) -> tuple[tuple[int, ...], str]:
        i = np.unravel_index(int(np.argmax(bad)), bad.shape)
        return i, (f"the sweep from {float(start[i])!r} to {float(stop[i])!r} Hz at "
                   f"{float(rate[i])!r} oct/min")
    few = ~(cycles >= MIN_SWEEP_CYCLES)
    if np.any(few):
        i, sweep = which(few)
        _fail(where, f"{sweep} passes {float(cycles[i]):.3g} cycles of its excitation, fewer "
              f"than {MIN_SWEEP_CYCLES:g}: that is no sweep", "give a slower rate or a wider "
              "frequency range (a launch sine sweep is 2-4 octaves per minute)")
    long = ~(duration <= MAX_SWEEP_DURATION)
    if np.any(long):
        i, sweep = which(long)
        _fail(where, f"{sweep} lasts {float(duration[i]):.3g} s, longer than "
              f"{MAX_SWEEP_DURATION:g} s", "give a faster rate (a launch sine sweep is 2-4 "
              "octaves per minute), or use base.frequency for a fixed frequency")
    cycles_up = given.get("base.sweep.ramp_cycles")
    if cycles_up is not None:
        rise = cycles_up / start
        slow = ~(rise <= 0.5 * duration)
        if np.any(slow):
            i = np.unravel_index(int(np.argmax(slow)), slow.shape)
            _fail("scene key 'base.sweep.ramp_cycles'", f"{cycles_up!r} cycles of "
                  f"{float(start[i])!r} Hz take {float(rise[i]):.3g} s, more than half the "
                  f"sweep ({float(duration[i]):.3g} s): the level would hardly reach the "
                  "table's", "give fewer cycles (default 10), or 0 for full level from t = 0")
    t_end = given.get("solver.t_end")
    longest = float(np.max(duration))
    if t_end is not None and t_end < longest * (1.0 - 1e-12):
        _fail("scene key 'solver.t_end'", f"{t_end!r} s ends before the sweep does "
              f"({longest:.6g} s at its longest): the sweep would be cut short",
              "remove solver.t_end (each point then ends with its own sweep), or give one "
              f"of at least {longest:.6g} s (after the sweep the clamps stop and the span "
              "rings down)")


def check_pairs(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Refuse both keys of an either-or pair (PAIRS), as scalars (given: dotted key -> value)
    or axes (axis name -> values)."""
    for pair in PAIRS:
        present = [d for d in pair if _present(d, given, axes)]
        if len(present) == 2:
            _fail(f"scene keys '{pair[0]}' and '{pair[1]}'", "give one, not both (as keys or "
                  f"axes {', '.join(schema.BY_DOTTED[d].axis or d for d in pair)})",
                  f"remove one of them: {_PAIR_UNITS[pair[0]]}")


def _check_transverse(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules of a transverse scene: no longitudinal-only keys, a controller for the method,
    a load frequency to sweep (none for a constant load), and model.coefficients = 'paper' with
    Table 1's cable only."""
    if given.get("solver.transits") is not None:
        _fail("scene key 'solver.transits'", "only for model.kind = 'longitudinal'",
              "use solver.t_end in seconds")
    for dotted, what in (("outputs.snapshot_times", "snapshots of the wave along the span"),
                         ("outputs.histories", "the end histories u(l, t), N(0, t)"),
                         ("outputs.normalised", "the N/P0 and v rho A a/P0 forms")):
        if given.get(dotted) not in (None, False):
            _fail(f"scene key '{dotted}'", f"only for model.kind = 'longitudinal' ({what}); a "
                  "transverse scene would ignore it",
                  "remove it, or use outputs.time_series = true for q(t)")
    if given.get("solver.method") == "dop853" and given.get("solver.controller") == "pi":
        _fail("scene keys 'solver.method' and 'solver.controller'",
              "the PI controller is tuned for method 'rk45' only",
              "use solver.controller = 'scipy' with method 'dop853'")
    _refuse_without(given, ("solver.intervals", "solver.courant"),
                    "only for model.kind = 'longitudinal' (its central-difference grid); a "
                    "transverse scene would ignore it", "remove the key")
    if given.get("load.type") == "constant":
        for axis in ("frequency_ratio", "frequency"):
            if axis in axes:
                _fail(f"axis '{axis}'", "load.type = 'constant' has no load frequency to sweep",
                      f"remove the {axis} axis, or use load.type = 'harmonic'")
        _refuse_frequency(given, "load.type = 'constant' has no load frequency; it would be "
                          "ignored", "remove the key, or use load.type = 'harmonic'")
    _check_load_frequency_axis(given, axes)
    _check_clamps(given, axes)
    _check_modes(given, axes)
    _check_continuation(given, axes)
    _check_stability(given, axes)
    _check_steady_stop(given, axes)
    if given.get("model.coefficients") == "paper":
        for axis in axes:
            if axis in PAPER_FIXED_AXES:
                _fail(f"axis '{axis}'", "model.coefficients = 'paper' has no such parameter",
                      "Eq.32 bakes in the Table 1 cable; use coefficients = 'consistent' "
                      "to sweep it")
        _check_paper_cable(given)


ROTATIONAL_STIFFNESS = "clamps.rotational_stiffness"


def _check_clamps(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules of [clamps] (docs/model.md sec. 10): one stretching (the clamps' axial stiffness
    or model.membrane, not both; none with the paper's Eq.32, whose is its own); a rotational
    stiffness with elastic clamps only, and always with them; a diameter (the bending strains)
    not where a pinned span under model.membrane reports none (sweep.models.loads.wanted),
    unless it is part of a data-sheet cable (sweep.models.cable); ends other than pins need the
    consistent coefficients (Eq.32 is the pinned span's)."""
    if _present("clamps.axial_stiffness", given, axes) and _present("model.membrane", given,
                                                                    axes):
        _fail(f"{_where('clamps.axial_stiffness', axes)} and "
              f"{_where('model.membrane', axes)}", "two stretchings: the clamps' axial stiffness "
              "sets the uniform tension between them, model.membrane the paper's local term",
              "remove model.membrane (the span then stretches as a whole between the clamps) or "
              "the axial stiffness")
    if (_present("clamps.axial_stiffness", given, axes)
            and given.get("model.coefficients") == "paper"):
        _fail(_where("clamps.axial_stiffness", axes), "model.coefficients = 'paper' is Eq.32 "
              "as printed, whose stretching is the paper's local term (alpha = 3/8): the "
              "clamps' axial stiffness would change nothing",
              "use model.coefficients = 'consistent' (the uniform tension between the "
              "clamps), or remove the axial stiffness")
    rotation = given.get("clamps.rotation", "pinned")
    stiffness = _present(ROTATIONAL_STIFFNESS, given, axes)
    if rotation != "elastic" and stiffness:
        _fail(_where(ROTATIONAL_STIFFNESS, axes), f"is for clamps.rotation = 'elastic' (a "
              f"rotational spring); the scene's clamps are '{rotation}'",
              "add rotation = 'elastic' to [clamps], or remove the stiffness")
    if rotation == "elastic" and not stiffness:
        _fail("scene key 'clamps.rotation'", "'elastic' clamps need their rotational stiffness",
              "add rotational_stiffness = 0.5 (N m/rad, each clamp) to [clamps], or an axis "
              "clamp_rotational_stiffness")
    if rotation == "pinned":
        # a data sheet's outer diameter describes the cable, used or not
        paper = given.get("model.coefficients") == "paper"
        if (_present("cable.diameter", given, axes)
                and (given.get("model.membrane") is not None or paper)
                and not cable.is_sheet(given, axes)):
            term = ("model.coefficients = 'paper', Eq.32 as printed" if paper
                    else "model.membrane")
            fix = ("use model.coefficients = 'consistent'" if paper
                   else "remove model.membrane (the uniform stretching tension)")
            _fail(_where("cable.diameter", axes), "is used for the bending strains, which a "
                  f"pinned span under the paper's local membrane term ({term}) does not "
                  "report", f"{fix}, or remove the diameter")
        return
    if given.get("model.coefficients") == "paper":
        _fail("scene key 'clamps.rotation'", f"model.coefficients = 'paper' is the pinned span's "
              f"Eq.32; '{rotation}' clamps need the consistent coefficients",
              "use model.coefficients = 'consistent', or clamps.rotation = 'pinned'")


def _check_load_frequency_axis(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Refuse an axis of the end load's frequency (frequency_ratio, frequency) in a scene
    without an end load (load.amplitude 0, its default, at every point): it would sweep
    nothing. A scene written for the old 4 N default is told to give its load."""
    if _has_end_load(given, axes):
        return
    for dotted in ("load.frequency_ratio", "load.frequency"):
        if schema.BY_DOTTED[dotted].axis in axes:
            _fail(_where(dotted, axes), "sweeps the end load's frequency, but the scene has no end load "
                  "(load.amplitude is 0, its default)", "give load.amplitude in N (e.g. "
                  "amplitude = 4.0 under [load], as the paper's case), or remove the axis; a "
                  "base excitation's frequency is base_frequency or base_frequency_ratio")


def _where(dotted: str, axes: dict[str, np.ndarray]) -> str:
    """How a message names key `dotted`: its [points] entry, its axis, or the scene key."""
    axis = schema.BY_DOTTED[dotted].axis
    if axis in getattr(axes, "zipped", ()):
        return f"[points] '{axis}'"
    return f"axis '{axis}'" if axis in axes else f"scene key '{dotted}'"


def _has_end_load(given: dict[str, Any], axes: dict[str, np.ndarray]) -> bool:
    """Whether the scene loads the span axially anywhere: load.amplitude (N, default 0), as a
    key or its axis, other than 0 at some point."""
    for dotted in LOAD_KEYS:
        axis = schema.BY_DOTTED[dotted].axis
        amplitude = axes[axis] if axis in axes else given.get(dotted)
        if amplitude is not None and np.any(np.asarray(amplitude, dtype=float) != 0.0):
            return True
    return False


def _refuse_frequency(given: dict[str, Any], problem: str, fix: str) -> None:
    """Refuse an end-load frequency where there is none to have: load.frequency, or a
    frequency_ratio other than the DEFAULT_FREQUENCY_RATIO every resolved scene writes out."""
    if given.get("load.frequency") is not None:
        _fail("scene key 'load.frequency'", problem, fix)
    if given.get("load.frequency_ratio") not in (None, DEFAULT_FREQUENCY_RATIO):
        _fail("scene key 'load.frequency_ratio'", problem, fix)


def _refuse_without(given: dict[str, Any], dependents: tuple[str, ...], problem: str,
                    fix: str) -> None:
    """Refuse any of `dependents` given with a value other than its default, when the key they
    depend on is absent (a default is accepted: a resolved scene writes every key out)."""
    for dotted in dependents:
        if dotted in given and given[dotted] != schema.BY_DOTTED[dotted].default:
            _fail(f"scene key '{dotted}'", problem, fix)


def _check_steady_stop(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """solver.stop_when_steady (kernels/metrics.py `steady_period`): at a fixed excitation
    frequency, each point solved on its own (any number of modes: the test watches the midspan
    deflection, and each mode's tail amplitude restarts with the midspan's window); its two
    settings need it."""
    if not given.get("solver.stop_when_steady"):
        _refuse_without(given, ("solver.steady_periods", "solver.steady_tolerance"),
                        "needs solver.stop_when_steady = true",
                        "add solver.stop_when_steady = true, or remove the key")
        return
    where = "scene key 'solver.stop_when_steady'"
    if given.get("continuation.axis") is not None:
        _fail(where, "not for a stepped sweep ([continuation]): each dwell carries its end "
              "state to the next", "remove it, or remove [continuation]")
    if any(_present(d, given, axes) for d in SWEEP_KEYS):
        _fail(where, "a swept base frequency is never steady", "remove it, or use a fixed "
              "base.frequency")


def _check_stability(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """outputs.stability needs a period: a harmonic end load (docs/model.md sec. 8), of an
    amplitude other than 0 at some point (without one the chart is a vacuous 'stable')."""
    if not given.get("outputs.stability"):
        return
    if not _has_end_load(given, axes):
        _fail("scene key 'outputs.stability'", "needs a harmonic end load: the scene's "
              "load.amplitude is 0, so there is no parametric excitation and every point "
              "would be a vacuous 'stable'", "give load.amplitude (N) or a load_amplitude "
              "axis, or remove outputs.stability")
    if given.get("load.type") == "constant":
        _fail("scene key 'outputs.stability'", "needs a harmonic end load (Floquet multipliers "
              "over its period); a constant load has none: its straight span is unstable above "
              "the buckling load, which every result holds (buckling_load, load_ratio)",
              "use load.type = 'harmonic', or remove outputs.stability")


def _check_modes(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules of model.modes: more than one mode needs the consistent coefficients (Eq.32 is one
    mode's), and each modal initial-condition list has one entry per mode and replaces the
    one-mode key (initial.displacement or initial.velocity, as a key or an axis)."""
    n_modes = given.get("model.modes", 1)
    if n_modes > 1 and given.get("model.coefficients") == "paper":
        _fail("scene key 'model.modes'", f"model.coefficients = 'paper' has one mode only "
              f"(Eq.32), got modes = {n_modes}",
              "use model.coefficients = 'consistent' for several modes, or remove model.modes")
    for listed, single in (("initial.modal_displacement", "initial.displacement"),
                           ("initial.modal_velocity", "initial.velocity")):
        values = given.get(listed)
        if values is None:
            continue
        if len(values) != n_modes:
            each = "q_1" if n_modes == 1 else f"q_1 .. q_{n_modes}"
            _fail(f"scene key '{listed}'", f"has {len(values)} entries for model.modes = "
                  f"{n_modes}", f"give one value per mode, {each} "
                  f"({schema.BY_DOTTED[listed].units})")
        if single in given or schema.BY_DOTTED[single].axis in axes:
            _fail(f"scene keys '{single}' and '{listed}'", "give one, not both",
                  f"remove {single} (mode 1 alone) or put its value first in {listed}")


def _check_continuation(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules of a stepped sweep ([continuation]): its axis is one of the scene's axes with more
    than one value, and the other continuation keys need it; the time series is not offered
    along a continued axis (every dwell restarts the clock)."""
    axis = given.get("continuation.axis")
    if axis is None:
        _refuse_without(given, ("continuation.direction", "continuation.jump_ratio"),
                        "needs continuation.axis (the axis to step along)",
                        "add continuation.axis = NAME, one of the scene's axes, or remove the "
                        "key")
        return
    if axis not in axes:
        named = ", ".join(axes) if axes else "none"
        _fail("scene key 'continuation.axis'", f"'{axis}' is not an axis of the scene (its "
              f"axes: {named})", "name one of the scene's axes, e.g. continuation.axis = "
              "'base_frequency' with that axis under [axes]")
    if len(axes[axis]) < 2:
        _fail("scene key 'continuation.axis'", f"axis '{axis}' has one value: nothing to step "
              "along", "give the axis two or more values")
    if given.get("outputs.time_series"):
        _fail("scene key 'outputs.time_series'", "not stored for a stepped sweep "
              "([continuation]): every step restarts the clock", "remove it, or remove "
              "[continuation] to store q(t) of independent points")


def _check_paper_cable(given: dict[str, Any]) -> None:
    """Refuse cable data that Eq.32 would ignore: its coefficients are numbers for the Table 1
    cable, so another modulus, density, area, inertia or membrane coefficient would not change
    the result. A value equal to Table 1's (PAPER_CABLE) is accepted, so that resolved scenes
    (every key written out) load back."""
    for dotted, table in PAPER_CABLE.items():
        value = given.get(dotted)
        if value is None or any(math.isclose(value, v, rel_tol=1e-9) for v in table):
            continue
        _fail(f"scene key '{dotted}'",
              f"model.coefficients = 'paper' ignores it: Eq.32 bakes in the Table 1 cable "
              f"({dotted} = {table[0]:g}), got {value:g}",
              "remove the key, or use model.coefficients = 'consistent' for another cable")


TRANSVERSE_ONLY = ("cable.damping_ratio", "initial.displacement", "initial.velocity",
                   "load.amplitude_ratio",
                   "initial.modal_displacement", "initial.modal_velocity",
                   "model.coefficients", "model.membrane", "model.paper_parametric", "solver.rtol", "solver.atol", "solver.method",
                   "solver.controller", "solver.driver", "solver.max_step", "solver.min_step",
                   "solver.first_step", "solver.steady_periods", "solver.steady_tolerance",
                   "metrics.tail", "metrics.tolerance", "outputs.amplitude",
                   "outputs.peak_amplitude", "outputs.settling_time", "outputs.response_period",
                   "outputs.absolute_acceleration", "outputs.time_series")
"""Keys of a transverse run that the longitudinal model (sweep/models/longitudinal.py, wave.py)
never reads: refused in a longitudinal scene with any value but their default."""


def _check_longitudinal(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules of a longitudinal scene: a constant load, its parameters only, one end time."""
    if given.get("outputs.stability"):
        _fail("scene key 'outputs.stability'", "only for model.kind = 'transverse' (Floquet "
              "multipliers of the span's transverse modes)", "remove it")
    if given.get("continuation.axis") is not None:
        _fail("scene key 'continuation.axis'", "only for model.kind = 'transverse' (a stepped "
              "sweep carries a span's transverse state); a longitudinal scene would ignore it",
              "remove [continuation]")
    _refuse_without(given, ("clamps.rotation",), "only for model.kind = 'transverse' (the "
                    "clamps' hold on the span's rotation sets its bending modes); a "
                    "longitudinal scene would ignore it", "remove [clamps]")
    for dotted in (ROTATIONAL_STIFFNESS, "clamps.axial_stiffness", "cable.diameter"):
        if given.get(dotted) is not None:
            _fail(f"scene key '{dotted}'", "only for model.kind = 'transverse'",
                  "remove [clamps]")
    _refuse_without(given, ("model.modes", "solver.stop_when_steady"),
                    "only for model.kind = 'transverse' (Galerkin modes, the steady early "
                    "stop); a longitudinal scene would ignore it", "remove the key")
    why = ("only for model.kind = 'transverse'; the longitudinal wave (undamped, from rest, a "
           "constant end load, central differences) would ignore it")
    _refuse_without(given, TRANSVERSE_ONLY, why, "remove the key")
    _refuse_frequency(given, why, "remove the key")
    load_type = given.get("load.type", LONGITUDINAL_LOAD)
    if load_type != LONGITUDINAL_LOAD:
        _fail("scene key 'load.type'",
              f"model.kind = 'longitudinal' takes only '{LONGITUDINAL_LOAD}'",
              "use load.type = 'constant', a suddenly applied end load (docs/model.md sec. 4), or "
              "model.kind = 'transverse' for a harmonic load")
    for axis in axes:
        if axis not in LONGITUDINAL_AXES:
            _fail(f"axis '{axis}'", "model.kind = 'longitudinal' has no such parameter",
                  f"remove the axis; it sweeps {', '.join(LONGITUDINAL_AXES)}")
    if all(given.get(k) is not None for k in END_TIME_KEYS):
        _fail("scene keys 'solver.t_end' and 'solver.transits'", "give one, not both",
              "remove one of them: t_end is in seconds, transits in multiples of l/a")


def _check_times(values: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Transverse: intervals and steps must fit inside the simulated time."""
    t_end = end_time(values, axes)
    for dotted in ("outputs.sample_interval", "solver.max_step", "solver.first_step",
                   "solver.min_step"):
        value = values[dotted]
        if value is not None and value > t_end:
            _fail(f"scene key '{dotted}'", f"must be <= solver.t_end ({t_end!r} s), got {value!r}",
                  "use a smaller value or a longer solver.t_end")
    low, high = values["solver.min_step"], values["solver.max_step"]
    if low is not None and high is not None and low > high:
        _fail("scene key 'solver.min_step'",
              f"must be <= solver.max_step ({high!r} s), got {low!r} (every step would be "
              "below the smallest allowed)", "use a smaller min_step or a larger max_step")
    _check_sample_count(values, "outputs.time_series", t_end)


def _check_sample_count(values: dict[str, Any], wanted: str, t_end: Any = None) -> None:
    """Refuse a sample interval that gives more than MAX_SAMPLES samples per point, when the
    samples are asked for (``wanted``) and the end time (t_end, s; default solver.t_end) is
    known."""
    t_end = values["solver.t_end"] if t_end is None else t_end
    interval = values["outputs.sample_interval"]
    if not values[wanted] or t_end is None or interval is None or t_end / interval <= MAX_SAMPLES:
        return
    _fail("scene key 'outputs.sample_interval'",
          f"{interval!r} s gives {t_end / interval:.3g} samples per point over "
          f"solver.t_end = {t_end!r} s, more than {MAX_SAMPLES}",
          f"use outputs.sample_interval >= {t_end / MAX_SAMPLES:.3g} s, or leave it out "
          "for t_end/1000")


def _extreme(values: dict[str, Any], axes: dict[str, np.ndarray], dotted: str,
             pick: Any) -> float:
    """`pick` (np.min or np.max) of a key over the grid: its axis, or its scalar value."""
    axis = schema.BY_DOTTED[dotted].axis
    return float(pick(axes[axis])) if axis in axes else float(values[dotted])


def _check_time_levels(values: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Longitudinal: the most time levels a span needs, t_end / dt with dt = C (l/N) / a
    (a = sqrt(E/rho)), must be a count the kernel can hold (<= LEVEL_LIMIT, about 4.6e18):
    a larger one overflowed int64 and ran nothing. A count above solver.max_steps but within
    the limit runs max_steps levels and is flagged max_steps_reached."""
    courant, n_int = values["solver.courant"], values["solver.intervals"]
    transits = values["solver.transits"]
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        if transits is not None:          # t_end = transits l/a: the count is the same for all
            levels = np.float64(transits) * n_int / courant
            keys = "solver.transits, solver.intervals and solver.courant"
        else:
            speed = np.sqrt(np.float64(_extreme(values, axes, "cable.youngs_modulus", np.max))
                            / _extreme(values, axes, "cable.density", np.min))
            levels = (np.float64(values["solver.t_end"]) * speed * n_int
                      / (courant * _extreme(values, axes, "cable.length", np.min)))
            keys = "solver.t_end, solver.intervals, solver.courant and the cable data"
    if math.isfinite(levels) and levels <= LEVEL_LIMIT:
        return
    _fail(f"scene keys {keys}",
          f"need {float(levels):.3g} time levels per span (t_end / dt, dt = courant l / "
          f"(intervals a)), more than any run can count ({LEVEL_LIMIT:.3g}; solver.max_steps = "
          f"{values['solver.max_steps']})",
          "use fewer transits or a shorter t_end, fewer intervals, or a courant number "
          "near 1")


def _warn_zero_solution(values: dict[str, Any], axes: dict[str, np.ndarray],
                        given: dict[str, Any]) -> None:
    """Transverse: warn (CableSweepWarning) when every point starts at q = q' = 0. The
    oscillator has no forcing term (the end load enters the stiffness only), so such a sweep
    stays at q = 0 everywhere: it would look like a result and say nothing. Base excitation
    with a level above zero somewhere drives the span from rest: no warning then."""
    if values.get(BASE_TABLE_KEY) is not None or random_scene.is_random(values):
        return                                      # a table's levels, a spectrum are > 0
    if values.get("outputs.stability"):             # its multipliers say what a seed would do
        return
    if has_base(values, axes) and any(
            _extreme(values, axes, d, np.max) > 0.0 for d in BASE_LEVEL_KEYS
            if values[d] is not None or schema.BY_DOTTED[d].axis in axes):
        return
    for dotted in ("initial.displacement", "initial.velocity"):
        if (_extreme(values, axes, dotted, np.min) != 0.0
                or _extreme(values, axes, dotted, np.max) != 0.0):
            return
    for dotted in ("initial.modal_displacement", "initial.modal_velocity"):
        if any(v != 0.0 for v in values.get(dotted) or ()):
            return
    what = ""
    if not given and not axes:
        what = (f"the scene sets no keys, so it runs one point of the defaults (a "
                f"{values['cable.length']:g} m span, {values['load.amplitude']:g} N "
                f"{values['load.type']} end load, {values['solver.t_end']:g} s): ")
    loaded = _has_end_load({k: values[k] for k in LOAD_KEYS}, axes)
    why = ("the end load only changes the stiffness" if loaded
           else "nothing drives the span (no end load, no base excitation)")
    warnings.warn(f"{what}initial.displacement = initial.velocity = 0 at every point, and "
                  f"{why}, so every point stays at q = 0 (state decayed, amplitude 0); give a "
                  "start, e.g. initial.displacement = 1e-4 (m)", CableSweepWarning,
                  stacklevel=5)


def _check_snapshot_times(values: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Longitudinal: with solver.t_end given, every snapshot time must be <= it; with
    solver.transits, <= the longest span's end time, transits x max(l sqrt(rho/E)) (a time
    after every span's end would be NaN everywhere)."""
    t_end, times = values["solver.t_end"], values["outputs.snapshot_times"]
    if not times:
        return
    if t_end is not None:
        for number, time in enumerate(times, start=1):
            if time > t_end:
                _fail("scene key 'outputs.snapshot_times'",
                      f"item {number} of the list, {time!r} s, is after solver.t_end "
                      f"({t_end!r} s)", "use times <= solver.t_end or a longer solver.t_end")
        return

    def extreme(dotted: str, pick: Any) -> float:
        axis = schema.BY_DOTTED[dotted].axis
        return float(pick(axes[axis])) if axis in axes else values[dotted]

    transits = values["solver.transits"]
    # As sweep.models.wave.wave_parameters computes it: transits x (l / a), a = sqrt(E/rho).
    latest = transits * (extreme("cable.length", np.max) / math.sqrt(
        extreme("cable.youngs_modulus", np.min) / extreme("cable.density", np.max)))
    for number, time in enumerate(times, start=1):
        if time > latest:
            _fail("scene key 'outputs.snapshot_times'",
                  f"item {number} of the list, {time!r} s, is after the end of every span "
                  f"(solver.transits = {transits!r} x l/a is at most {latest:.6g} s)",
                  f"use times <= {latest:.6g} s, or more solver.transits")


_CHECKED_COEFFICIENTS: dict[str, tuple[str, ...]] = {
    "transverse": ("k0", "k1", "g0", "g1", "h", "omega", "mass", "damping", "q_scale",
                   "v_scale", "natural_frequency", "buckling_load", "load_ratio", "base_accel",
                   "base_omega"),
    "longitudinal": ("wave_speed", "axial_stiffness", "t_end", "transit_time",
                     "static_end_displacement", "impedance"),
}


def _float64(value: Any) -> Any:
    """A float as np.float64 (IEEE overflow and division by zero give inf, not exceptions)."""
    return np.float64(value) if isinstance(value, float) else value


_PLAUSIBLE = (1e-100, 1e100)
"""Magnitudes outside this range are named first when derived coefficients are not finite."""


def _check_coefficients(values: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Refuse cable data whose derived coefficients are not finite floats (e.g. density =
    5e-324 makes w1^2 = EI k^4 / (rho A) infinite; E = 1e-300 with rho = 1e308 a zero wave
    speed): computed with the run's own formulas (sweep.models.oscillator,
    sweep.models.wave.wave_parameters) at every corner of the grid (each axis at its first
    and last value). Each coefficient is a product of powers of the parameters (or a sum of
    same-signed ones), so its largest and smallest magnitudes lie at corners. [points]
    entries are combinations of their own: every entry is a corner (`Swept.corners`)."""
    kind = values["model.kind"]
    columns = Swept.of(axes).corners()
    params: dict[str, Any] = {name: columns.get(name, _float64(values[key.dotted]))
                              for name, key in schema.BY_AXIS.items()}
    as_given = params                   # what the messages name (not a data sheet's equivalents)
    params = cable.resolve(params, values)
    if params["inertia"] is None:
        params["inertia"] = default_inertia(params["area"])
    params.update(coefficients=values["model.coefficients"], load_type=values["load.type"],
                  clamps_rotation=values.get("clamps.rotation"),
                  paper_parametric=values["model.paper_parametric"],
                  divergence_bound=values["metrics.divergence_bound"],
                  base_levels_g=values.get(BASE_TABLE_KEY))
    if params["load_type"] == "constant":
        params["frequency"] = None
    with np.errstate(all="ignore"):
        if kind != "longitudinal":
            load_from_ratio(params)
        if kind == "longitudinal":
            derived = wave_parameters(params, values["solver.t_end"], values["solver.transits"])
        else:
            derived = oscillator(params)
        table = params["base_levels_g"]
        levels = ([] if table is None or kind == "longitudinal" else
                  [("base_levels", np.array([g for _, g in table]) * schema.STANDARD_GRAVITY)])
    bad = [(name, np.atleast_1d(np.asarray(derived[name], dtype=np.float64)))
           for name in _CHECKED_COEFFICIENTS[kind]] + levels
    bad = [(name, v) for name, v in bad if not np.all(np.isfinite(v))]
    if not bad:
        if kind == "transverse":
            _check_fixed_frequency_in_table(values, axes, params, derived)
            _check_base_frequency_ratio(values, axes, params, derived)
            _check_stability_frequency(values, axes, derived)
            if random_scene.is_random(values):
                random_scene.check_accuracy(values, derived["natural_frequency"],
                                            params["damping_ratio"])
                random_scene.check_spectra_window(values, derived["natural_frequency"],
                                                  params["damping_ratio"])
        return
    name, coefficient = bad[0]
    corner = int(np.argmax(~np.isfinite(coefficient))) if coefficient.size > 1 else 0
    inputs = []
    for axis, key in schema.BY_AXIS.items():
        value = as_given[axis]
        if value is None or key.section not in ("cable", "model", "load", "base"):
            continue
        value = float(np.atleast_1d(value)[corner % np.size(value)])
        where = (f"scene key '{key.dotted}' = {value!r}" if axis not in axes
                 else f"[points] '{axis}' entry {value!r}" if axis in getattr(axes, "zipped", ())
                 else f"axis '{axis}' at {value!r}")
        inputs.append((not (value == 0 or _PLAUSIBLE[0] <= abs(value) <= _PLAUSIBLE[1]), where))
    if table is not None and not all(math.isfinite(g * schema.STANDARD_GRAVITY)
                                     for _, g in table):
        inputs.append((True, f"scene key '{BASE_TABLE_KEY}'"))
    named = [w for odd, w in inputs if odd] or [w for _, w in inputs]
    base_level = any(f"'{d}'" in w or f"'{schema.BY_DOTTED[d].axis}'" in w for w in named
                     for d in BASE_LEVEL_KEYS + (BASE_TABLE_KEY,))
    _fail(", ".join(named),
          f"give the derived coefficient {name} = {float(coefficient[corner])!r}, not a "
          f"finite float64 (so are: {', '.join(n for n, _ in bad)})",
          "give the base level in g of a physical size, e.g. base.acceleration_g = 1.0 or "
          "levels_g = [[5.0, 0.5], [100.0, 0.6]] (Hz, g)" if base_level else
          "give the cable data in SI units with physical magnitudes, e.g. cable.density = "
          "8900 kg/m^3, cable.area = 6e-6 m^2, cable.youngs_modulus = 1.1e11 Pa")


def _check_fixed_frequency_in_table(values: dict[str, Any], axes: dict[str, np.ndarray],
                                    params: dict[str, Any], derived: dict[str, Any]) -> None:
    """Refuse a fixed base frequency outside the level table (base.levels_g): the table has
    no level there. The frequency (base.frequency in Hz, or base.frequency_ratio times each
    span's f1) is checked at every corner of the grid, where its extremes lie (a product of
    powers of the parameters, as `_check_coefficients` says)."""
    table = params["base_levels_g"]
    if table is None or params.get("base_sweep_start") is not None:
        return
    if params.get("base_frequency") is None and params.get("base_frequency_ratio") is None:
        return
    frequency = np.atleast_1d(np.asarray(derived["base_omega"], np.float64)) / (2.0 * np.pi)
    low, high = table[0][0], table[-1][0]
    outside = (frequency < low * (1 - 1e-12)) | (frequency > high * (1 + 1e-12))
    if not np.any(outside):
        return
    f = float(frequency[int(np.argmax(outside))])
    dotted = "base.frequency" if params.get("base_frequency") is not None \
        else "base.frequency_ratio"
    _fail(f"{_where(dotted, axes)} and scene key '{BASE_TABLE_KEY}'", f"the base frequency reaches "
          f"{f:.6g} Hz, outside the table's {low:g} to {high:g} Hz (no level there)",
          "extend the table to every base frequency of the scene, or give a constant level "
          "with base.acceleration_g")


MAX_BASE_RATIO = 1e6
"""Highest base frequency over f1: beyond it the span follows its clamps rigidly (the
response is (4/pi) A / w^2, below round-off of the quasi-static one) and an explicit step
would have to resolve the excitation for ever."""


def _check_base_frequency_ratio(values: dict[str, Any], axes: dict[str, np.ndarray],
                                params: dict[str, Any], derived: dict[str, Any]) -> None:
    """Refuse a base frequency (fixed, or a sweep's highest) above MAX_BASE_RATIO x f1 at
    any corner of the grid."""
    if derived.get("participation") is None or not np.any(np.asarray(derived["participation"])):
        return
    with np.errstate(all="ignore"):
        f1 = np.asarray(derived["natural_frequency"], np.float64)
        if params.get("base_sweep_start") is not None:
            top = np.maximum(np.asarray(params["base_sweep_start"], np.float64),
                             np.asarray(params["base_sweep_stop"], np.float64))
        else:
            top = np.asarray(derived["base_omega"], np.float64) / (2.0 * np.pi)
        ratio = np.atleast_1d(top / f1)
    if not np.any(ratio > MAX_BASE_RATIO):
        return
    keys = [d for d in ("base.frequency", "base.frequency_ratio", "base.sweep.start",
                        "base.sweep.stop") if values.get(d) is not None
            or schema.BY_DOTTED[d].axis in axes]
    _fail(", ".join(f"scene key '{d}'" for d in keys) or "scene section '[base]'",
          f"the base frequency reaches {float(np.max(ratio)):.3g} times the span's f1, above "
          f"{MAX_BASE_RATIO:g}: the span follows its clamps rigidly there, and no step could "
          "resolve the excitation", "give base frequencies in Hz of a launch environment "
          "(5-2000 Hz)")


MAX_STABILITY_RATIO = 1e4
"""Highest W/w1 of a stability chart. The parametric resonances of a span lie at
W = (w_i + w_j) / n, below 2 w_N (50 w1 with five pinned modes); far above them one load
period is so short that a multiplier's distance from 1 (about 2 pi zeta w1 / W) falls below
the integration error (at W/w1 = 1e9 a damped span came out 'unstable')."""


def _check_stability_frequency(values: dict[str, Any], axes: dict[str, np.ndarray],
                               derived: dict[str, Any]) -> None:
    """Refuse outputs.stability at a load frequency above MAX_STABILITY_RATIO w1 (at any
    corner of the grid, where W/w1's extremes lie)."""
    if not values.get("outputs.stability") or values["load.type"] != "harmonic":
        return
    with np.errstate(all="ignore"):
        ratio = np.atleast_1d(np.asarray(derived["omega"], np.float64)
                              / (2.0 * np.pi * np.asarray(derived["natural_frequency"])))
    if not np.any(ratio > MAX_STABILITY_RATIO):
        return
    dotted = ("load.frequency" if values.get("load.frequency") is not None
              or "frequency" in axes else "load.frequency_ratio")
    _fail(f"{_where(dotted, axes)} with outputs.stability", f"the load frequency reaches "
          f"W/w1 = {float(np.max(ratio)):.3g}, above {MAX_STABILITY_RATIO:g}: far above every "
          "parametric resonance, where one load period is too short for its Floquet "
          "multiplier to be told from 1", f"keep W/w1 <= {MAX_STABILITY_RATIO:g} (the "
          "resonances lie at W = 2 w1 / n and between the modes' sums)")


def _shared_defaults(values: dict[str, Any], mentioned: set[str]) -> None:
    """Defaults of every kind: load.frequency_ratio 1.0 without a load frequency, no
    load.amplitude (N) where load.amplitude_ratio gives the load, and cable.inertia (m^4)
    from a scalar area."""
    if not any(d in mentioned for d in FREQUENCY_KEYS):
        values["load.frequency_ratio"] = DEFAULT_FREQUENCY_RATIO
    if "load.amplitude_ratio" in mentioned:         # the load in N comes from the ratio
        values["load.amplitude"] = None
    cable.defaults(values, mentioned)
    if "cable.inertia" not in mentioned and values["cable.area"] is not None:
        values["cable.inertia"] = default_inertia(values["cable.area"])


def points_per_basis(values: Mapping[str, Any], swept: Swept, skip: str | None = None) -> int:
    """How many points of the grid share one kernel call on the lanes (at least): all of them,
    but with elastic clamps whose bases do not stack into one call (`family_shares_lanes`)
    only the points along the axes (and [points]) that leave K = k_t l / EI as it is
    (`BASIS_KEYS_EXEMPT`, and every key outside [cable] and the clamps' rotational
    stiffness); the axis `skip` not counted (a stepped sweep's: its lines share a call)."""
    elastic = (values["clamps.rotation"] == "elastic"
               and not family_shares_lanes(values, swept))

    def moves_basis(name: str) -> bool:
        dotted = schema.BY_AXIS[name].dotted
        return elastic and (dotted == "clamps.rotational_stiffness" or (
            dotted.startswith("cable.") and dotted not in BASIS_KEYS_EXEMPT))

    count = 1
    for name, axis in swept.items():
        if name not in swept.zipped and name != skip and not moves_basis(name):
            count *= len(axis)
    if swept.zipped and not any(moves_basis(name) for name in swept.zipped):
        count *= len(swept[next(iter(swept.zipped))])
    return count


def family_shares_lanes(values: Mapping[str, Any], swept: Swept) -> bool:
    """Whether the spans of a scene with elastic clamps, each K = k_t l / EI its own basis,
    run in one lanes call (kernels.modes.stacked: bases of the same polynomial structure,
    model.modes where `basis.elastic_bases_stack`, every k_t > 0; k_t = 0 is the pinned span's
    closed-form basis, of another form)."""
    from .basis import elastic_bases_stack
    name = schema.BY_DOTTED["clamps.rotational_stiffness"].axis
    stiffness = swept[name] if name in swept else values["clamps.rotational_stiffness"]
    return (stiffness is not None and elastic_bases_stack(int(values["model.modes"]))
            and bool(np.all(np.asarray(stiffness, float) > 0.0)))


def _transverse_defaults(values: dict[str, Any], given: dict[str, Any],
                         mentioned: set[str], swept: Swept) -> None:
    """solver.t_end 5 s, DOP853 for several modes (MULTI_MODE_METHOD) and the scalar driver
    where fewer than LANES_LEAST_POINTS points share a basis (RANDOM_LANES_LEAST_POINTS
    points x records for a random scene, RANDOM_ONE_MODE_LANES_LEAST_POINTS with one mode),
    and the paper preset's initial.velocity without an initial condition."""
    _shared_defaults(values, mentioned)
    if random_scene.is_random(values):
        random_scene.defaults(values, mentioned)
        if values["model.modes"] > 1:
            least, points = RANDOM_LANES_LEAST_POINTS, points_per_basis(values, swept)
        else:       # one mode: every point in one call, whatever the clamps
            least = RANDOM_ONE_MODE_LANES_LEAST_POINTS
            points = points_per_basis({**values, "clamps.rotation": "pinned"}, swept)
        if ("solver.driver" not in mentioned
                and points * values["base.realisations"] < least):
            values["solver.driver"] = "scalar"
    elif values["model.modes"] > 1:
        if "solver.method" not in mentioned:
            values["solver.method"] = MULTI_MODE_METHOD
        if ("solver.driver" not in mentioned
                and points_per_basis(values, swept, skip=values["continuation.axis"])
                < LANES_LEAST_POINTS):
            values["solver.driver"] = "scalar"
    swept = any(d in mentioned for d in SWEEP_KEYS)
    if "solver.t_end" not in mentioned and not swept and not random_scene.is_random(values):
        values["solver.t_end"] = DEFAULT_T_END     # a sweep's points end with their sweeps
    if swept:            # no settling; the peaks over the whole sweep; the lanes for one mode
        # and no variable that means nothing for a sweep: no response period (the frequency
        # never stops changing), no tail amplitude where the tail is the whole sweep (it
        # would be peak_amplitude again)
        whole = "metrics.tail" not in mentioned
        several = values["model.modes"] > 1     # the lanes take a sweep of one mode
        for dotted, value in (("outputs.settling_time", False),
                              ("solver.driver", "scalar" if several else "lanes"),
                              ("metrics.tail", 1.0), ("solver.max_steps", SWEEP_MAX_STEPS),
                              ("outputs.response_period", False)) + (
                                  (("outputs.amplitude", False),) if whole else ()):
            if dotted not in mentioned:
                values[dotted] = value
    paper = values["model.coefficients"] == "paper"
    if paper and not ("initial.displacement" in mentioned or "initial.velocity" in mentioned):
        values["initial.velocity"] = PAPER_VELOCITY


def _longitudinal_defaults(values: dict[str, Any], given: dict[str, Any],
                           mentioned: set[str], swept: Swept) -> None:
    """load.type 'constant', and 8 transits without an end time."""
    _shared_defaults(values, mentioned)
    values["load.type"] = given.get("load.type", LONGITUDINAL_LOAD)
    if not any(d in mentioned for d in END_TIME_KEYS):
        values["solver.transits"] = DEFAULT_TRANSITS


PLAUSIBLE = (
    ("cable.length", 5.0, "m", "a clamp spacing is a few cm to a metre: was it in mm? write "
     "e.g. '150 mm'"),
    ("cable.linear_mass", 5.0, "kg/m", "a harness cable or bundle weighs grams to a kilogram or "
     "two a metre: was it the data sheet's g/m? write e.g. '53.4 g/m'"),
    ("cable.diameter", 0.1, "m", "was it in mm? write e.g. '2.76 mm'"),
    ("cable.damping_ratio", 0.5, "of critical", "a cable's is about 0.005-0.1: was it a "
     "percentage? 2 % is 0.02"),
)
"""(key, largest plausible value, its unit as shown, the hint): a plain number is SI, and a
data sheet's number typed without its unit lands far above these (a warning, not a refusal:
the physics allows them)."""
PLAUSIBLE_LOW = (
    ("cable.length", 0.01, "m", "a clamp spacing is a few cm to a metre: was it in mm where m "
     "were meant? write e.g. '150 mm'"),
    ("cable.axial_rigidity", 1e3, "N", "a harness cable's EA is kN to MN: 'mN' is "
     "milli-newtons, 'MN' mega; write e.g. '1.65 MN'"),
    ("cable.bending_rigidity", 1e-6, "N m^2", "even a thin wire's EI is above 1e-5 N m^2: was "
     "it in N mm^2? write e.g. '0.1 N m^2'"),
    ("cable.linear_mass", 1e-4, "kg/m", "a harness wire weighs a gram or more a metre: write "
     "e.g. '53.4 g/m'"),
)
"""(key, smallest plausible value, its unit as shown, the hint): a unit mistyped by a factor of
1e6 ('mN' for 'MN') or a plain number in the wrong unit lands far below these (a warning:
a stretching span whose EA is 1e-3 N does not stretch, silently)."""


def _warn_implausible(values: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Warn, one line a key, where a key of PLAUSIBLE is above its largest plausible value at
    some point of the grid."""
    for table, extreme, beyond, word in ((PLAUSIBLE, np.max, np.greater, "more"),
                                         (PLAUSIBLE_LOW, np.min, np.less, "less")):
        for dotted, bound, units, hint in table:
            axis = schema.BY_DOTTED[dotted].axis
            if axis not in axes and values.get(dotted) is None:
                continue
            value = _extreme(values, axes, dotted, extreme)
            if beyond(value, bound):
                warnings.warn(f"{dotted} = {value:g} {units} (plain numbers are SI) is {word} "
                              f"than {bound:g} {units}: {hint}", CableSweepWarning, stacklevel=5)


def _check_transverse_resolved(values: dict[str, Any], axes: dict[str, np.ndarray],
                               given: dict[str, Any]) -> None:
    """Finite coefficients, steps and samples within t_end, the zero-solution warning and a
    warning for a cable far from a harness's (PLAUSIBLE)."""
    _check_coefficients(values, axes)
    _check_times(values, axes)
    _warn_zero_solution(values, axes, given)
    _warn_implausible(values, axes)


def _check_longitudinal_resolved(values: dict[str, Any], axes: dict[str, np.ndarray],
                                 given: dict[str, Any]) -> None:
    """Finite coefficients, a countable number of time levels, snapshots within the end time,
    and the history sample count."""
    _check_coefficients(values, axes)
    _check_time_levels(values, axes)
    _check_snapshot_times(values, axes)
    _check_sample_count(values, "outputs.histories")
    if not _has_end_load(given, axes):
        warnings.warn("load.amplitude = 0 at every point (the default: no end load), and a "
                      "longitudinal scene is the wave an end load sends, so every point stays "
                      "at rest; give load.amplitude in N, e.g. amplitude = 4.0 under [load] as "
                      "the paper's case", CableSweepWarning, stacklevel=5)


@dataclass(frozen=True)
class Rules:
    """The scene rules of one model kind, in the order the scene pipeline calls them.

    check(given, axes): refuse keys and axes the kind cannot take (given: dotted key -> the
        checked value; axes: axis name -> values), before any default is applied.
    defaults(values, given, mentioned, swept): write the kind's defaults into `values` (every
        dotted key -> value, the schema's defaults applied); `mentioned`: the keys given or
        swept; `swept`: the axes and [points] (their values).
    check_resolved(values, axes, given): refuse (or warn about) the resolved scene.
    """

    check: Callable[[dict[str, Any], dict[str, np.ndarray]], None]
    defaults: Callable[[dict[str, Any], dict[str, Any], set[str], Swept], None]
    check_resolved: Callable[[dict[str, Any], dict[str, np.ndarray], dict[str, Any]], None]


RULES: dict[str, Rules] = {
    "transverse": Rules(_check_transverse, _transverse_defaults, _check_transverse_resolved),
    "longitudinal": Rules(_check_longitudinal, _longitudinal_defaults,
                          _check_longitudinal_resolved),
}
"""model.kind -> its rules (the keys of sweep.models.MODELS)."""
