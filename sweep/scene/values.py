"""Scene files: load a sweep description from TOML, validate it, and write it back.

A scene is a TOML document (see docs/architecture.md) checked against the table in `sweep.schema`.
`load_scene` takes a built-in name (a file in ``sweep/scenes/``) or a path, applies
``KEY=VALUE`` overrides to the parsed document, validates everything, and returns a
`Scene`: every scalar key resolved (defaults applied) plus one float64 array per axis.

Every mistake a user can make raises `SceneError` with a one-line message of the form
``WHERE: what is wrong (how to fix it)``, where WHERE names the dotted key, axis or file.
A scene argument that names no built-in scene and no file is reported as a missing file
when it looks like a path (holds a '/' or ends in .toml), else as an unknown name. A scene
file is read as bytes (at most MAX_SCENE_BYTES) and parsed as TOML: nothing in it is executed.

Kinds of value (`sweep.schema`): "float", "int", "bool", "str", and "floats", a TOML list
of finite numbers (may be empty, each within the key's bounds; ints accepted, bools not).
A "floats" value is stored as a tuple of Python floats, e.g. ``outputs.snapshot_times``.

Resolution rules worth knowing:
- A key swept under ``[axes]`` has ``values[key] = None``; its values live in ``axes``.
  If the key is also given as a scalar, the axis wins.
- ``load.frequency`` and ``load.frequency_ratio`` are alternatives; if neither is given,
  ``load.frequency_ratio = 1.0``.
- An override that sets a sweepable key as a scalar removes that key's axis, an override
  of one load frequency key removes the other, and an override of one end-time key
  (``solver.t_end``, ``solver.transits``) removes the other, so ``--set`` can always
  replace what the scene file says.
- ``solver.courant`` above 1 is refused whatever the model (the scheme is unstable there).
- ``cable.inertia`` not given: `default_inertia` of the area, the bending moment of a solid
  round section, A^2 / (4 pi). With ``area`` swept, ``values["cable.inertia"]`` is None and the
  inertia follows the area point by point (`sweep.grid.parameters`).

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
- An override of one spelling removes the other, as for the load frequency.

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
"""

from __future__ import annotations

import difflib
import itertools
import math
import os
import re
import stat
import tomllib
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from importlib import resources
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from .. import schema
from ..errors import CableSweepWarning, SceneError

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

from sweep.kernels.wave_layout import LEVEL_LIMIT  # noqa: E402  (most time levels a span counts)

FREQUENCY_KEYS: tuple[str, str] = ("load.frequency", "load.frequency_ratio")
DEFAULT_FREQUENCY_RATIO = 1.0

BASE_LEVEL_KEYS: tuple[str, str] = ("base.acceleration", "base.acceleration_g")
BASE_FREQUENCY_KEYS: tuple[str, str] = ("base.frequency", "base.frequency_ratio")
BASE_KEYS: tuple[str, ...] = BASE_LEVEL_KEYS + BASE_FREQUENCY_KEYS
BASE_FIX = ("add a [base] table with acceleration or acceleration_g and frequency or "
            "frequency_ratio")
"""How to fix a base key or axis given without the rest of the base excitation."""
PAIRS: tuple[tuple[str, str], ...] = (FREQUENCY_KEYS, BASE_LEVEL_KEYS, BASE_FREQUENCY_KEYS)
"""Either-or keys: two spellings of one quantity (as scalars or axes), never both."""
_PAIR_UNITS: dict[str, str] = {
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

LONGITUDINAL_AXES: tuple[str, ...] = ("length", "load_amplitude", "youngs_modulus", "density",
                                      "area")
"""The axes a longitudinal scene can sweep (the parameters of the wave problem)."""
LONGITUDINAL_LOAD = "constant"
RANGE_KEYS: tuple[str, ...] = ("start", "stop", "num", "spacing")
LOG_DIGITS = 15
"""Significant digits of the values of a log-spaced range (its endpoints are kept exactly)."""
MAX_AXIS_POINTS = 10_000_000
MAX_INT = 2**63 - 1
"""Largest size of an integer key's value (int64; larger ones cannot even be compared as floats)."""
MAX_SAMPLES = 10_000_000
"""Most time-series samples per point (solver.t_end / outputs.sample_interval)."""
MAX_SCENE_BYTES = 8 * 2**20
"""A scene file longer than this (bytes) is refused before it is read; 8 MiB holds an axis of
400 000 values written out (parsed in about 1 s, 70 MB)."""

_VALUE_SECTIONS: tuple[str, ...] = tuple(s for s in schema.SECTIONS if s != "axes")
_COMMON_AXES = ("length", "load_amplitude", "frequency_ratio", "frequency", "damping_ratio")
_SWEEPABLE_TEXT = ", ".join(dict.fromkeys([*(a for a in _COMMON_AXES if a in schema.BY_AXIS),
                                          *schema.BY_AXIS]))
_BUILTIN_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_TOML_POSITION = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")
_TOML_AT_END = re.compile(r"\s*\(at end of document\)\s*$")

# How to fix an out-of-range value, for the keys users most often get wrong.
_HINTS: dict[str, str] = {
    "cable.length": "give the span length in metres",
    "cable.density": "give the density in kg/m^3, e.g. 8900 for copper",
    "cable.area": "give the cross-sectional area in m^2, e.g. 6e-6 for 6 mm^2",
    "cable.inertia": "give the bending second moment of area in m^4, e.g. 2.865e-12 (a solid "
                     "round 6 mm^2 section), or leave it out for A^2/(4 pi)",
    "cable.youngs_modulus": "give Young's modulus in Pa, e.g. 1.1e11 for copper",
    "cable.damping_ratio": "give the damping ratio as a fraction of critical, e.g. 0.02 for 2 %",
    "model.membrane": "use 0.375 (the paper), 0.25 (classical stretching) or 0 (none)",
    "load.frequency_ratio": "give the load frequency as a multiple of w1, e.g. 2.0",
    "load.frequency": "give the load frequency in Hz",
    "base.acceleration": "give the peak base acceleration in m/s^2, e.g. 4.9, or use "
                         "base.acceleration_g",
    "base.acceleration_g": "give the peak base acceleration in g, e.g. 0.5",
    "base.frequency": "give the base excitation frequency in Hz, e.g. 20.0",
    "base.frequency_ratio": "give the base excitation frequency as a multiple of f1, e.g. 1.0",
    "solver.t_end": "give the simulated time in seconds, e.g. 5.0",
    "solver.transits": "give the end time in wave transits l/a, e.g. 8.0",
    "solver.intervals": "give the number of spatial intervals per span, e.g. 1000",
    "solver.courant": "use 1.0, which is exact at the nodes",
    "outputs.snapshot_times": "give the snapshot times in seconds, e.g. [0.0001, 0.0002]",
    "solver.rtol": "use e.g. 1e-8; typical values are 1e-6 to 1e-10",
    "solver.atol": "give a small positive absolute tolerance, e.g. 1e-12 (m for q)",
    "solver.max_steps": "give a positive step budget, e.g. 1000000",
    "metrics.tail": "give the tail window as a fraction of t_end, e.g. 0.5",
    "metrics.tolerance": "give a relative tolerance, e.g. 0.02",
    "run.threads": "give a thread count, or 0 for all cores",
}


# --------------------------------------------------------------------------- the Scene


@dataclass(frozen=True, eq=False)
class Scene:
    """A validated, fully resolved scene.

    values: every dotted key of `schema.KEYS` -> its value (defaults applied); None for an
        optional key that is absent and for a key that is swept (see ``axes``). A "floats"
        key (``outputs.snapshot_times``) holds a tuple of floats, or None.
    axes: axis name -> 1-D read-only float64 array, in scene order ([axes] table order,
        then axes added by overrides).
    text: the TOML text as read; source: the built-in name or the path given;
    overrides: the overrides applied, with parsed values.

    Two scenes are equal when their name, description, values and axes are equal
    (text, source and overrides are not compared).
    """

    name: str
    description: str
    values: dict[str, Any]
    axes: dict[str, np.ndarray]
    text: str = field(repr=False)
    source: str
    overrides: dict[str, Any] = field(default_factory=dict)

    @property
    def has_base(self) -> bool:
        """Whether the scene has base excitation of the clamps (a [base] level and frequency)."""
        return has_base(self.values, self.axes)

    def get(self, dotted: str) -> Any:
        """The resolved value of a dotted key, e.g. ``scene.get("solver.rtol")``.

        A "floats" key gives a tuple of floats (possibly empty) or None.
        """
        return self.values[dotted]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Scene):
            return NotImplemented
        return (self.name == other.name
                and self.description == other.description
                and self.values == other.values
                and list(self.axes) == list(other.axes)
                and all(np.array_equal(self.axes[a], other.axes[a]) for a in self.axes))

    __hash__ = None  # type: ignore[assignment]

    def to_toml(self) -> str:
        """The resolved scene as TOML: every section, defaults included, axes as lists.

        None-valued keys are left out; a "floats" value is written as a list. `load_scene_text`
        of the result gives an equal Scene.
        """
        lines = [f"# Resolved scene from {_comment_text(self.source)}: "
                 "defaults written out, axes as explicit lists."]
        if self.overrides:
            lines.append(f"# Overrides applied: {_comment_text(', '.join(self.overrides))}.")
        lines.append(f"name = {_toml_value(self.name)}")
        lines.append(f"description = {_toml_value(self.description)}")
        for section in _VALUE_SECTIONS:
            lines.extend(self._section_lines(section))
        if self.axes:
            lines.extend(["", "[axes]"])
            lines.extend(f"{_toml_key(a)} = {_toml_array(v)}" for a, v in self.axes.items())
        return "\n".join(lines) + "\n"

    def _section_lines(self, section: str) -> list[str]:
        """``[section]`` and its non-None keys, in schema order; empty if none."""
        body = [f"{key.name} = {_toml_value(self.values[key.dotted])}"
                for key in schema.KEYS
                if key.section == section and self.values[key.dotted] is not None]
        return ["", f"[{section}]", *body] if body else []


# --------------------------------------------------------------------------- public API


def load_scene(scene: str | os.PathLike, overrides: Mapping[str, Any] | None = None) -> Scene:
    """Load a built-in scene by name, or a scene file by path, and validate it.

    overrides: dotted key -> value, applied to the document before validation. Values may be
    Python values or strings; strings are parsed as TOML values (see `parse_override`).
    """
    source, text, default_name = _read_scene(scene)
    return _build(text, source, default_name, overrides)


def load_scene_text(text: str, source: str = "<string>",
                    overrides: Mapping[str, Any] | None = None) -> Scene:
    """Like `load_scene`, from TOML text; ``source`` is used in error messages."""
    return _build(text, source, "unnamed", overrides)


def builtin_scenes() -> dict[str, str]:
    """Built-in scene name -> the first line of its description, sorted by name."""
    found: dict[str, str] = {}
    try:
        entries = list(_scenes_dir().iterdir())
    except OSError:
        return {}
    for entry in entries:
        if entry.name.endswith(".toml") and entry.is_file():
            found[entry.name[:-len(".toml")]] = _first_description_line(entry.read_text("utf-8"))
    return dict(sorted(found.items()))


def parse_override(item: str) -> tuple[str, Any]:
    """Split ``"KEY=VALUE"`` into the dotted key and the value parsed as a TOML value.

    A VALUE that is not valid TOML is kept as the raw string, so ``model.coefficients=paper``
    works as well as ``model.coefficients="paper"``.
    """
    key, sep, value = item.partition("=")
    key = key.strip()
    if not sep or not key:
        _fail(f"override '{item}'", "must have the form KEY=VALUE",
              "write a dotted scene key, '=' and a value, e.g. solver.rtol=1e-9 or "
              "axes.length=[0.5, 1.0]")
    return key, _parse_value_text(value)


# --------------------------------------------------------------------------- reading


def _scenes_dir() -> Any:
    """The package-data folder of built-in scenes (works from an installed wheel too)."""
    return resources.files("sweep") / "scenes"


def _builtin_file(name: str) -> Any | None:
    """The built-in scene file called ``name``, or None."""
    if not _BUILTIN_NAME.fullmatch(name):
        return None
    try:
        candidate = _scenes_dir() / f"{name}.toml"
        return candidate if candidate.is_file() else None
    except OSError:
        return None


def _read_scene(scene: str | os.PathLike) -> tuple[str, str, str]:
    """(source, text, default name) of a built-in name or a scene file path.

    Only a regular file of at most MAX_SCENE_BYTES is read (a FIFO would block, a device
    never ends); every OS error (permissions, a name too long, ...) is a one-line SceneError.
    """
    if isinstance(scene, str):
        builtin = _builtin_file(scene)
        if builtin is not None:
            return scene, builtin.read_text("utf-8"), scene
    source = os.fspath(scene)
    if isinstance(source, bytes):
        source = os.fsdecode(source)
    where = f"scene file '{source}'"
    info = _stat_scene(source, where)
    if info is None:
        if _looks_like_path(source):
            _fail(where, "no such file", "check the path; 'sweep scenes' lists the built-in names")
        _fail(f"scene '{source}'", "no built-in scene of that name and no such file",
              "run 'sweep scenes' for the built-in names")
    _check_text(where, source, "the file name", "give the file (and its folders) a UTF-8 name")
    if stat.S_ISDIR(info.st_mode):
        _fail(where, "is a directory, not a TOML file", "give the path of a .toml scene file")
    data = _read_regular(source, where)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        _fail(where, f"is not UTF-8 text (bad byte at offset {exc.start})",
              "save the file as UTF-8")
    return source, text, Path(source).stem or "unnamed"


def _stat_scene(source: str, where: str) -> os.stat_result | None:
    """os.stat of a scene path (following links); None when nothing is there."""
    if not source:
        return None
    try:
        return os.stat(source)
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        _fail(where, f"cannot be read: {exc.strerror or exc}", "check the path and its permissions")
    except ValueError as exc:                    # an embedded NUL character
        _fail(where, f"is not a valid path ({exc})", "check the path")


def _read_regular(source: str, where: str) -> bytes:
    """The bytes of a regular file of at most MAX_SCENE_BYTES (opened without blocking, so a
    FIFO put in its place is refused instead of waited on)."""
    fix = "give a TOML scene file; write long axes as range tables {start, stop, num}"
    too_large = f"is larger than {MAX_SCENE_BYTES // 2**20} MiB"
    try:
        fd = os.open(source, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        _fail(where, f"cannot be read: {exc.strerror or exc}", "check the path and its permissions")
    with os.fdopen(fd, "rb") as handle:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            _fail(where, f"is not a regular file (a {_file_kind(info.st_mode)})",
                  "give the path of a .toml scene file")
        if info.st_size > MAX_SCENE_BYTES:
            _fail(where, f"{too_large} ({info.st_size:,} bytes)", fix)
        try:
            data = handle.read(MAX_SCENE_BYTES + 1)
        except OSError as exc:
            _fail(where, f"cannot be read: {exc.strerror or exc}",
                  "check the path and its permissions")
    if len(data) > MAX_SCENE_BYTES:
        _fail(where, too_large, fix)
    return data


def _file_kind(mode: int) -> str:
    """'FIFO', 'character device', ... for a file mode that is not a regular file."""
    kinds = ((stat.S_ISFIFO, "FIFO (named pipe)"), (stat.S_ISCHR, "character device"),
             (stat.S_ISBLK, "block device"), (stat.S_ISSOCK, "socket"))
    return next((name for test, name in kinds if test(mode)), "special file")


def _check_text(where: str, text: str, what: str, fix: str) -> None:
    """Refuse text that cannot be stored as a netCDF attribute: not encodable as UTF-8 (lone
    surrogates, e.g. undecodable bytes of a command-line argument) or holding a NUL character
    (netCDF would drop it silently)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        _fail(where, f"{what} is not valid UTF-8 text (character {exc.start + 1})", fix)
    if "\x00" in text:
        _fail(where, f"{what} holds a NUL character (character {text.index(chr(0)) + 1})", fix)


def _looks_like_path(source: str) -> bool:
    """Whether a scene argument that names nothing was meant as a file, not a built-in name."""
    return (os.sep in source or "/" in source or (os.altsep or "/") in source
            or source.lower().endswith(".toml"))


def _first_description_line(text: str) -> str:
    """The first line of a scene's ``description``, or "" if it has none."""
    try:
        description = tomllib.loads(text).get("description", "")
    except (ValueError, RecursionError):         # TOMLDecodeError is a ValueError
        return ""
    lines = description.strip().splitlines() if isinstance(description, str) else []
    return lines[0] if lines else ""


def _parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse scene text; a syntax error names the file, line and column."""
    try:
        return tomllib.loads(text)
    except RecursionError:
        _fail(f"scene file '{source}'", "arrays or tables are nested too deeply to parse",
              "write at most a few levels of nested [...] and {...}")
    except tomllib.TOMLDecodeError as exc:
        message = str(exc)
        position = _TOML_POSITION.search(message)
        if position:
            where = f"at line {position.group(1)}, column {position.group(2)}"
            message = message[:position.start()]
        elif _TOML_AT_END.search(message):
            where = "at the end of the file"
            message = _TOML_AT_END.sub("", message)
        else:
            where = "somewhere"
        _fail(f"scene file '{source}'", f"TOML syntax error {where}: {message}",
              "fix the line and run again")
    except ValueError as exc:                    # e.g. an integer of more than 4300 digits
        _fail(f"scene file '{source}'", f"cannot be parsed: {_value_error_text(exc)}",
              "fix the value and run again")


def _value_error_text(exc: ValueError) -> str:
    """What tomllib's plain ValueError (not a syntax error) means, in a few words."""
    message = str(exc)
    if "integer string conversion" in message:
        return "an integer has more than 4300 digits"
    return message


# --------------------------------------------------------------------------- overrides


def _parse_value_text(text: str) -> Any:
    """A TOML value from text, or the stripped text itself if it is not one."""
    try:
        parsed = tomllib.loads("v = " + text)
    except (ValueError, RecursionError):         # TOMLDecodeError is a ValueError
        return text.strip()
    return parsed["v"] if list(parsed) == ["v"] else text.strip()


def _expects_string(dotted: str) -> bool:
    """Whether a dotted key holds a string (so a raw string override is taken as is)."""
    if dotted in schema.TOP_LEVEL:
        return True
    key = schema.BY_DOTTED.get(dotted)
    return key is not None and key.kind == "str"


def _override_value(dotted: str, value: Any) -> Any:
    """An override's value as a plain Python value; strings are parsed as TOML values."""
    if not isinstance(value, str):
        return _plain(value)
    parsed = _parse_value_text(value)
    if _expects_string(dotted) and not isinstance(parsed, str):
        return value
    return parsed


def _plain(value: Any) -> Any:
    """Numpy scalars/arrays and tuples -> Python scalars and lists, recursively."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (np.ndarray, tuple, list)):
        return [_plain(v) for v in (value.tolist() if isinstance(value, np.ndarray) else value)]
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _parse_overrides(overrides: Mapping[str, Any] | None) -> dict[str, Any]:
    """Check override keys and parse their values; refuse both keys of an either-or pair."""
    parsed: dict[str, Any] = {}
    for key, value in (overrides or {}).items():
        if not isinstance(key, str) or not key.strip():
            _fail(f"override {key!r}", "has no key",
                  "write KEY=VALUE with a dotted scene key, e.g. solver.rtol=1e-9")
        key = key.strip()
        parsed[key] = _override_value(key, value)
    for pair in PAIRS:
        if len({_pair_target(k, pair) for k in parsed} - {None}) == 2:
            _fail(f"overrides '{pair[0]}' and '{pair[1]}'", "give one, not both",
                  "remove one of the two overrides")
    if all(k in parsed for k in END_TIME_KEYS):
        _fail("overrides 'solver.t_end' and 'solver.transits'", "give one, not both",
              "remove one of the two overrides")
    return parsed


def _pair_target(dotted: str, pair: tuple[str, str]) -> str | None:
    """The key of an either-or `pair` an override sets (as scalar or axis), or None."""
    if dotted in pair:
        return dotted
    if dotted.startswith("axes."):
        axis = _axis_or_none(dotted[len("axes."):])
        if axis is not None and schema.BY_AXIS[axis].dotted in pair:
            return schema.BY_AXIS[axis].dotted
    return None


def _apply_overrides(doc: dict[str, Any], overrides: Mapping[str, Any]) -> None:
    """Write overrides into the parsed document (in place), before validation."""
    for dotted, value in overrides.items():
        section, _, name = dotted.partition(".")
        if not name:
            doc[dotted] = value
        elif section == "axes":
            _override_axis(doc, name, value)
        else:
            _override_scalar(doc, section, name, value)


def _override_table(doc: dict[str, Any], section: str) -> dict[str, Any]:
    """The document's ``[section]`` table, created if absent."""
    table = doc.setdefault(section, {})
    if not isinstance(table, dict):
        _section_not_table(section, table)
    return table


def _override_axis(doc: dict[str, Any], name: str, value: Any) -> None:
    """Set or replace an axis (keeping its place); drop the other key of its either-or pair
    (load or base frequency, base level)."""
    axes = _override_table(doc, "axes")
    axis = _axis_or_none(name)
    if axis is None:
        axes[name] = value
        return
    _drop_frequency_partner(doc, schema.BY_AXIS[axis].dotted)
    replaced = {(axis if _axis_or_none(k) == axis else k): v for k, v in axes.items()}
    replaced[axis] = value
    axes.clear()
    axes.update(replaced)


def _override_scalar(doc: dict[str, Any], section: str, name: str, value: Any) -> None:
    """Set a scalar key; it replaces an axis on the same key, or the other end-time key."""
    table = _override_table(doc, section)
    table[name] = value
    dotted = f"{section}.{name}"
    if dotted in END_TIME_KEYS:
        table.pop(END_TIME_KEYS[1 - END_TIME_KEYS.index(dotted)].partition(".")[2], None)
    key = schema.BY_DOTTED.get(dotted)
    if key is not None and key.axis is not None:
        _drop_axis(doc, key.axis)
        _drop_frequency_partner(doc, key.dotted)


def _drop_axis(doc: dict[str, Any], axis: str) -> None:
    """Remove every ``[axes]`` entry that names ``axis``."""
    axes = doc.get("axes")
    if isinstance(axes, dict):
        for entry in [k for k in axes if _axis_or_none(k) == axis]:
            del axes[entry]


def _drop_frequency_partner(doc: dict[str, Any], dotted: str) -> None:
    """When one key of an either-or pair (PAIRS: the load frequency, the base level, the base
    frequency) is set, remove the other (scalar and axis)."""
    pair = next((p for p in PAIRS if dotted in p), None)
    if pair is None:
        return
    partner = schema.BY_DOTTED[pair[1 - pair.index(dotted)]]
    table = doc.get(partner.section)
    if isinstance(table, dict):
        table.pop(partner.name, None)
    _drop_axis(doc, partner.axis or "")


# --------------------------------------------------------------------------- validation


def _build(text: str, source: str, default_name: str,
           overrides: Mapping[str, Any] | None) -> Scene:
    """Parse, override, validate and resolve a scene."""
    doc = _parse_toml(text, source)
    if isinstance(doc.get("axes"), dict):
        doc["axes"] = _flatten_axes(doc["axes"])
    file_has_base = "base" in doc
    applied = _parse_overrides(overrides)
    _apply_overrides(doc, applied)
    _check_top_level(doc)
    name = _check_name(doc.get("name", default_name))
    description = _check_description(doc.get("description", ""))
    given = _check_sections(doc)
    axes = _check_axes(doc.get("axes", {}))
    _check_base(doc, given, axes, file_has_base)
    _check_model(given, axes)
    _check_run(given)
    _check_frequency_pair(given, axes)
    values = _resolve(given, axes)
    _check_coefficients(values, axes)
    if values["model.kind"] == "longitudinal":
        _check_time_levels(values, axes)
        _check_snapshot_times(values, axes)
        _check_sample_count(values, "outputs.histories")
    else:
        _check_times(values)
        _warn_zero_solution(values, axes, given)
    return Scene(name=name, description=description, values=values, axes=axes,
                 text=text, source=source, overrides=applied)


def _flatten_axes(table: dict[str, Any]) -> dict[str, Any]:
    """``[axes] cable.length = ...`` parses as a nested table: make it ``"cable.length"``."""
    flat: dict[str, Any] = {}
    for entry, value in table.items():
        if entry in _VALUE_SECTIONS and isinstance(value, dict):
            flat.update({f"{entry}.{name}": v for name, v in value.items()})
        else:
            flat[entry] = value
    return flat


def _check_top_level(doc: dict[str, Any]) -> None:
    """Only ``name``, ``description`` and the schema's sections may appear at the top."""
    for key, value in doc.items():
        if key in schema.TOP_LEVEL:
            continue
        if key in schema.SECTIONS:
            if not isinstance(value, dict):
                _section_not_table(key, value)
            continue
        _unknown_top_level(key, value)


def _section_not_table(section: str, value: Any) -> NoReturn:
    _fail(f"scene key '{section}'", f"must be a table ([{section}] section), got {_show(value)}",
          f"write [{section}] on a line of its own, with its keys below it")


def _unknown_top_level(key: str, value: Any) -> NoReturn:
    """Report an unknown top-level key or section, with a suggestion."""
    if isinstance(value, dict) and value:
        first = next(iter(value))
        section = _close(key, _VALUE_SECTIONS)
        guess = _guess_key(first, section) if section else _guess_key(first)
        _fail(f"scene key '{key}.{first}'", f"unknown section '{key}'",
              _suggestion(guess or section, _SECTIONS_TEXT))
    guess = _close(key, [*schema.TOP_LEVEL, *schema.SECTIONS]) or _guess_key(key)
    _fail(f"scene key '{key}'", "unknown top-level key", _suggestion(guess, _SECTIONS_TEXT))


_SECTIONS_TEXT = ("remove it, or move it into its section: the top level holds name, "
                  "description and the sections "
                  + ", ".join(f"[{s}]" for s in schema.SECTIONS))


def _guess_key(name: str, section: str | None = None) -> str | None:
    """The dotted key a misspelt ``name`` most likely means: first in ``section``, then anywhere.

    E.g. ('lenght', 'cable') -> 'cable.length'; ('amplitude', 'cable') -> 'load.amplitude'.
    """
    if section is not None:
        in_section = _close(name, [k.name for k in schema.KEYS if k.section == section])
        if in_section:
            return f"{section}.{in_section}"
    anywhere = _close(name, [k.name for k in schema.KEYS])
    return next((k.dotted for k in schema.KEYS if k.name == anywhere), None)


def _check_name(value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        _fail("scene key 'name'", f"must be a non-empty string, got {_show(value)}",
              'write e.g. name = "my-sweep"')
    _check_text("scene key 'name'", value, "the name", 'write e.g. name = "my-sweep"')
    return value


def _check_description(value: Any) -> str:
    if not isinstance(value, str):
        _fail("scene key 'description'", f"must be a string, got {_show(value)}",
              'write e.g. description = "what the sweep is for"')
    _check_text("scene key 'description'", value, "the description",
                'write e.g. description = "what the sweep is for"')
    return value


def _check_sections(doc: dict[str, Any]) -> dict[str, Any]:
    """Validate every scalar key present in the sections; dotted key -> value."""
    given: dict[str, Any] = {}
    for section in _VALUE_SECTIONS:
        for name, raw in doc.get(section, {}).items():
            dotted = f"{section}.{name}"
            key = schema.BY_DOTTED.get(dotted)
            if dotted == "run.scheduler":
                _fail(f"scene key '{dotted}'", "a scene cannot choose the dask cluster it runs "
                      "on (connecting lets the cluster run code in this process)",
                      "remove it, and pass --scheduler tcp://HOST:8786 on the command line, "
                      "or sweep.run(scene, scheduler=...)")
            if key is None:
                _unknown_section_key(section, dotted)
            given[dotted] = _check_value(f"scene key '{dotted}'", key, raw)
    return given


def _unknown_section_key(section: str, dotted: str) -> NoReturn:
    valid = [k.name for k in schema.KEYS if k.section == section]
    fallback = f"remove it, or use one of the valid keys in [{section}]: {', '.join(valid)}"
    _fail(f"scene key '{dotted}'", "unknown key",
          _suggestion(_guess_key(dotted.partition(".")[2], section), fallback))


def _check_value(where: str, key: schema.Key, raw: Any) -> Any:
    """A value of the key's kind, within its bounds and choices."""
    if key.kind == "floats":
        return _as_floats(where, key, raw)
    if isinstance(raw, (dict, list)):
        _fail(where, f"must be a single value, got {_show(raw)}", _container_fix(key, raw))
    if key.kind == "float":
        value: Any = _as_float(where, raw, _example(key))
    elif key.kind == "int":
        value = _as_int(where, raw, _example(key))
    elif key.kind == "bool":
        value = _as_bool(where, key, raw)
    else:
        value = _as_choice(where, key, raw)
    if key.dotted == "solver.courant" and value > 1.0:
        _fail(where, f"must be <= 1, got {_show(value)}", _courant_fix(value))
    if key.kind in ("float", "int"):
        _check_bounds(where, key, value)
    return value


def _as_floats(where: str, key: schema.Key, raw: Any) -> tuple[float, ...]:
    """A tuple of finite floats from a list of numbers (may be empty), each within bounds."""
    fix = f"write e.g. {key.name} = [0.0001, 0.0002]"
    if not isinstance(raw, list):
        _fail(where, f"must be a list of numbers, got {_show(raw)}", fix)
    values = []
    for number, item in enumerate(raw, start=1):
        if isinstance(item, bool) or not isinstance(item, (int, float)):
            _fail(where, f"item {number} of the list must be a number, got {_show(item)}", fix)
        try:
            value = float(item)
        except OverflowError:
            value = math.inf
        if not math.isfinite(value):
            _fail(where, f"item {number} of the list must be a finite number, got {_show(item)}",
                  fix)
        if not _within(key, np.array(value)):
            _fail(where, f"item {number} of the list must be {_bounds_text(key)}, "
                         f"got {_show(item)}", _HINTS.get(key.dotted) or _generic_hint(key))
        values.append(value)
    return tuple(values)


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


def _container_fix(key: schema.Key, raw: Any) -> str:
    """How to fix a list or table given where a single value is expected."""
    if isinstance(raw, list) and key.axis is not None:
        return f"to sweep it, put it under [axes] as {key.axis} = [...]"
    if isinstance(raw, list):
        return f"{key.dotted} cannot be swept; {_example(key)}"
    return _example(key)


def _example(key: schema.Key) -> str:
    """'write e.g. rtol = 1e-08', or a generic hint for keys without a default."""
    if key.default is None:
        if key.dotted in _HINTS:
            return _HINTS[key.dotted]
        return f"write e.g. {key.name} = 1.0" if key.kind == "float" else "give a single value"
    return f"write e.g. {key.name} = {_toml_value(key.default)}"


def _as_float(where: str, raw: Any, fix: str) -> float:
    """A finite float from an int or float (never a bool)."""
    if isinstance(raw, bool) or not isinstance(raw, (int, float)):
        _fail(where, f"must be a number, got {_show(raw)}", fix)
    try:
        value = float(raw)
    except OverflowError:
        value = math.inf
    if not math.isfinite(value):
        _fail(where, f"must be a finite number, got {_show(raw)}", fix)
    return value


def _as_int(where: str, raw: Any, fix: str) -> int:
    """An int from an int or an integral float such as 1e6 (never a bool)."""
    value = _as_float(where, raw, fix) if isinstance(raw, float) else raw
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        _fail(where, f"must be a whole number, got {_show(raw)}", fix)
    if isinstance(value, float) and not value.is_integer():
        _fail(where, f"must be a whole number, got {_show(raw)}", fix)
    if abs(value) > MAX_INT:
        _fail(where, f"must be at most {MAX_INT:,} in size, got {_show(raw)}", fix)
    return int(value)


def _as_bool(where: str, key: schema.Key, raw: Any) -> bool:
    if not isinstance(raw, bool):
        _fail(where, f"must be true or false, got {_show(raw)}",
              f"write {key.name} = true or {key.name} = false, without quotes")
    return raw


def _as_choice(where: str, key: schema.Key, raw: Any) -> str:
    """A string, one of the key's choices if it has any."""
    if not isinstance(raw, str):
        _fail(where, f"must be a string, got {_show(raw)}", f'write {key.name} = "..." with quotes')
    _check_text(where, raw, "the value", f'write {key.name} = "..." in UTF-8 text')
    if key.choices and raw not in key.choices:
        listed = ", ".join(f"'{c}'" for c in key.choices)
        _fail(where, f"must be one of {listed}, got {_show(raw)}",
              _suggestion(_close(raw, key.choices), "use one of those"))
    return raw


def _check_bounds(where: str, key: schema.Key, values: Any) -> None:
    """Refuse a scalar, or the first element of an axis, outside the key's bounds."""
    array = np.atleast_1d(np.asarray(values, dtype=float))
    bad = ~_within(key, array)
    if not bad.any():
        return
    fix = _HINTS.get(key.dotted) or _generic_hint(key)
    if np.ndim(values) == 0:
        _fail(where, f"must be {_bounds_text(key)}, got {_show(values)}", fix)
    value = float(array[np.argmax(bad)])
    _fail(where, f"value {_show(value)} is out of range: must be {_bounds_text(key)}", fix)


def _within(key: schema.Key, array: np.ndarray) -> np.ndarray:
    """Elementwise: does each value satisfy the key's minimum and maximum?"""
    ok = np.ones(array.shape, dtype=bool)
    if key.minimum is not None:
        ok &= array > key.minimum if key.exclusive_min else array >= key.minimum
    if key.maximum is not None:
        ok &= array < key.maximum if key.exclusive_max else array <= key.maximum
    return ok


def _bounds_text(key: schema.Key) -> str:
    """E.g. '> 0 m' or '>= 1e-14 and <= 0.1'."""
    units = f" {key.units}" if key.units not in ("", "1") else ""
    if key.units == schema.G_UNITS:
        units = " g"
    parts = []
    if key.minimum is not None:
        parts.append(f"{'>' if key.exclusive_min else '>='} {key.minimum:g}{units}")
    if key.maximum is not None:
        parts.append(f"{'<' if key.exclusive_max else '<='} {key.maximum:g}{units}")
    return " and ".join(parts)


def _generic_hint(key: schema.Key) -> str:
    units = f" in {key.units}" if key.units not in ("", "1") else ""
    return f"give the {key.long_name or key.name}{units} within that range"


# --------------------------------------------------------------------------- axes


def _check_axes(table: dict[str, Any]) -> dict[str, np.ndarray]:
    """Validate ``[axes]``: axis name -> read-only float64 array, in table order."""
    axes: dict[str, np.ndarray] = {}
    for entry, raw in table.items():
        axis = _axis_name(entry)
        if axis in axes:
            _fail(f"axis '{entry}'", f"axis '{axis}' is given twice", "keep one of the entries")
        axes[axis] = _axis_values(axis, raw)
    return axes


def _axis_or_none(entry: str) -> str | None:
    """The axis an ``[axes]`` entry name means (axis name or sweepable dotted key), or None."""
    if entry in schema.BY_AXIS:
        return entry
    key = schema.BY_DOTTED.get(entry)
    return key.axis if key is not None else None


def _axis_name(entry: str) -> str:
    """The axis an ``[axes]`` entry names; refuse unknown and non-sweepable names."""
    axis = _axis_or_none(entry)
    if axis is not None:
        return axis
    sweepable = _SWEEPABLE_TEXT
    key = schema.BY_DOTTED.get(entry)
    same_name = [k for k in schema.KEYS if k.name == entry]
    if key is None and same_name and all(k.axis is None for k in same_name):
        key = same_name[0]
    if key is not None:
        _fail(f"axis '{entry}'", f"'{key.dotted}' cannot be swept",
              f"sweepable: {sweepable}; set {key.dotted} as a single value in [{key.section}]")
    candidates = [*schema.BY_AXIS, *(k.dotted for k in schema.BY_AXIS.values())]
    guess = _close(entry, candidates) or next((k.axis for k in same_name if k.axis), None)
    _fail(f"axis '{entry}'", "unknown axis",
          _suggestion(guess, f"use one of the sweepable axes; sweepable: {sweepable}"))


def _axis_values(axis: str, raw: Any) -> np.ndarray:
    """An axis's values from a list or a range table, checked against the key's bounds."""
    where = f"axis '{axis}'"
    if isinstance(raw, list):
        values = _axis_list(where, raw)
    elif isinstance(raw, dict):
        values = _axis_range(where, raw)
    else:
        _fail(where, f"must be a list of values or a range table, got {_show(raw)}",
              f"write e.g. {axis} = [0.5, 1.0] or {axis} = {{start = 0.5, stop = 1.0, num = 11}}")
    _check_monotonic(where, values)
    _check_bounds(where, schema.BY_AXIS[axis], values)
    values.flags.writeable = False
    return values


def _axis_list(where: str, raw: list) -> np.ndarray:
    if not raw:
        _fail(where, "empty list", "give at least one value")
    fix = "give a list of numbers, e.g. [0.5, 0.7, 1.0]"
    return np.array([_as_float(where, v, fix) for v in raw], dtype=np.float64)


def _axis_range(where: str, raw: dict) -> np.ndarray:
    """Values of a ``{start, stop, num, spacing}`` table (linear or log)."""
    fix = "write e.g. {start = 0.5, stop = 3.0, num = 26, spacing = \"linear\"}"
    unknown = [k for k in raw if k not in RANGE_KEYS]
    if unknown:
        _fail(where, f"unknown key '{unknown[0]}' in range table",
              f"remove it; a range table takes only {', '.join(RANGE_KEYS)}")
    missing = [k for k in ("start", "stop", "num") if k not in raw]
    if missing:
        _fail(where, f"range table needs '{missing[0]}'", fix)
    start = _as_float(where, raw["start"], fix)
    stop = _as_float(where, raw["stop"], fix)
    num = _as_int(where, raw["num"], fix)
    if not 1 <= num <= MAX_AXIS_POINTS:
        _fail(where, f"num must be between 1 and {MAX_AXIS_POINTS}, got {_show(raw['num'])}", fix)
    spacing = raw.get("spacing", "linear")
    if spacing not in schema.AXIS_SPACINGS:
        _fail(where, f"spacing must be one of {', '.join(schema.AXIS_SPACINGS)}, "
                     f"got {_show(spacing)}", 'write spacing = "linear" or spacing = "log"')
    if spacing == "log":
        if start <= 0 or stop <= 0:
            _fail(where, f"log spacing needs start and stop > 0, got start = {start!r}, "
                         f"stop = {stop!r}", 'use positive limits or spacing = "linear"')
        return log_range(start, stop, num)
    return linear_range(start, stop, num)


def linear_range(start: float, stop: float, num: int) -> np.ndarray:
    """``num`` evenly spaced values from start to stop, each the float nearest to its exact value.

    start and stop are read as the decimals they print as (``repr``: what a user wrote, e.g.
    0.3), and value i is the exact rational (start (num-1-i) + stop i) / (num-1) rounded once
    to float64. So {start = 0.3, stop = 1.2, num = 10} gives 0.4, not linspace's
    0.39999999999999997, and the endpoints are start and stop exactly.
    """
    if num == 1:
        return np.array([start], dtype=np.float64)
    first, last = Fraction(repr(start)), Fraction(repr(stop))
    scale = math.lcm(first.denominator, last.denominator)
    a, b = int(first * scale), int(last * scale)
    steps = num - 1
    denominator = scale * steps
    if max(abs(a), abs(b)) * steps < 2**53 and denominator < 2**53:
        # Every integer here is exact in float64, so one IEEE division rounds correctly.
        i = np.arange(num, dtype=np.int64)
        numerators = a * (steps - i) + b * i
        return numerators.astype(np.float64) / float(denominator)
    # Python's int / int is correctly rounded at any size.
    return np.fromiter(((a * (steps - i) + b * i) / denominator for i in range(num)),
                       dtype=np.float64, count=num)


def log_range(start: float, stop: float, num: int) -> np.ndarray:
    """``num`` log-spaced values from start to stop (both > 0), rounded to LOG_DIGITS
    significant digits, endpoints exact.

    A value that is a short decimal (1, 10, 100, 1000 for {start = 1, stop = 1000, num = 4})
    is that decimal's float exactly; any other is within 5e-15 relative of start (stop /
    start)^(i / (num - 1)) (plus float64 geomspace's few ulps where long double is double). If rounding would merge neighbours, the unrounded values are kept.
    """
    # In long double where the platform has it: within an ulp of the exact value before rounding.
    values = np.geomspace(np.longdouble(start), np.longdouble(stop), num).astype(np.float64)
    rounded = np.fromiter((float(f"{v:.{LOG_DIGITS}g}") for v in values), dtype=np.float64,
                          count=num)
    rounded[0], rounded[-1] = start, stop
    steps = np.diff(rounded)
    if np.all(steps > 0) or np.all(steps < 0):
        return rounded
    values[0], values[-1] = start, stop
    return values


def _check_monotonic(where: str, values: np.ndarray) -> None:
    steps = np.diff(values)
    if not (np.all(steps > 0) or np.all(steps < 0)):
        _fail(where, "values must be strictly increasing or strictly decreasing",
              "sort them and remove duplicates")


# --------------------------------------------------------------------------- cross-key rules


def _model_kind(given: dict[str, Any]) -> str:
    return given.get("model.kind", schema.BY_DOTTED["model.kind"].default)


def _check_model(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules tied to model.kind and model.coefficients."""
    if _model_kind(given) == "longitudinal":
        _check_longitudinal(given, axes)
        return
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
    if given.get("load.type") == "constant":
        for axis in ("frequency_ratio", "frequency"):
            if axis in axes:
                _fail(f"axis '{axis}'", "load.type = 'constant' has no load frequency to sweep",
                      f"remove the {axis} axis, or use load.type = 'harmonic'")
    if given.get("model.coefficients") == "paper":
        for axis in axes:
            if axis in PAPER_FIXED_AXES:
                _fail(f"axis '{axis}'", "model.coefficients = 'paper' has no such parameter",
                      "Eq.32 bakes in the Table 1 cable; use coefficients = 'consistent' "
                      "to sweep it")
        _check_paper_cable(given)


def _check_run(given: dict[str, Any]) -> None:
    """run.workers sizes the LocalCluster of the dask backend; with threads it would be
    ignored (run.threads is the threads backend's count)."""
    if given.get("run.workers", 0) and given.get("run.backend", "threads") != "dask":
        _fail("scene key 'run.workers'", "only for run.backend = 'dask' (the LocalCluster's "
              "worker processes); the threads backend would ignore it",
              "use run.threads for the threads backend, or set run.backend = 'dask'")


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


def _check_longitudinal(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Rules of a longitudinal scene: a constant load, its parameters only, one end time."""
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


def _check_frequency_pair(given: dict[str, Any], axes: dict[str, np.ndarray]) -> None:
    """Refuse both keys of an either-or pair (PAIRS), as scalars or axes."""
    for pair in PAIRS:
        present = [d for d in pair if d in given or schema.BY_DOTTED[d].axis in axes]
        if len(present) == 2:
            _fail(f"scene keys '{pair[0]}' and '{pair[1]}'", "give one, not both (as keys or "
                  f"axes {', '.join(schema.BY_DOTTED[d].axis or d for d in pair)})",
                  f"remove one of them: {_PAIR_UNITS[pair[0]]}")


def has_base(values: Mapping[str, Any], axes: Mapping[str, Any]) -> bool:
    """Whether a resolved scene (its values and axes) has base excitation: a base level is
    given, as a [base] key or an axis (a validated scene then has a base frequency too)."""
    return any(values.get(d) is not None or schema.BY_DOTTED[d].axis in axes
               for d in BASE_LEVEL_KEYS)



def _check_base(doc: dict[str, Any], given: dict[str, Any], axes: dict[str, np.ndarray],
                file_has_base: bool) -> None:
    """Rules of base excitation (docs/model.md sec. 5): a [base] table or base axis needs a
    level and a frequency (each as a key or an axis), a transverse scene and the consistent
    coefficients. `file_has_base`: the scene file itself (before overrides) has a [base]
    table; if not (a lone base axis, an override), the fix says to add the table."""
    named = [(f"axis '{schema.BY_DOTTED[d].axis}'" if schema.BY_DOTTED[d].axis in axes
              else f"scene key '{d}'")
             for d in BASE_KEYS if d in given or schema.BY_DOTTED[d].axis in axes]
    if not named and "base" not in doc:
        return
    where = named[0] if named else "scene section '[base]'"
    if _model_kind(given) == "longitudinal":
        _fail(where, "model.kind = 'longitudinal' has no base excitation (the clamps' "
              "transverse motion drives the transverse modal equation only)",
              "remove the [base] table and the base axes, or use model.kind = 'transverse'")
    if given.get("model.coefficients") == "paper":
        _fail(where, "model.coefficients = 'paper' has no base excitation (Eq.32 as printed "
              "has no forcing term)", "use model.coefficients = 'consistent'")
    for pair, what, example in ((BASE_LEVEL_KEYS, "a level", "acceleration_g = 0.5 (g) or "
                                 "acceleration = 4.9 (m/s^2)"),
                                (BASE_FREQUENCY_KEYS, "a frequency", "frequency = 20.0 (Hz) or "
                                 "frequency_ratio = 1.0 (f/f1)")):
        if any(d in given or schema.BY_DOTTED[d].axis in axes for d in pair):
            continue
        _fail(where, f"base excitation needs {what}: the scene gives neither "
              f"{pair[0]} nor {pair[1]} (as a key or axis)",
              BASE_FIX if not file_has_base else f"add {example} to the [base] table")


def _resolve(given: dict[str, Any], axes: dict[str, np.ndarray]) -> dict[str, Any]:
    """Every dotted key -> value: given, else default; None for swept keys."""
    swept = {schema.BY_AXIS[a].dotted for a in axes}
    values = {k.dotted: None if k.dotted in swept else given.get(k.dotted, k.default)
              for k in schema.KEYS}

    def mentioned(dotted: str) -> bool:
        return dotted in given or dotted in swept

    if not any(mentioned(d) for d in FREQUENCY_KEYS):
        values["load.frequency_ratio"] = DEFAULT_FREQUENCY_RATIO
    if not mentioned("cable.inertia") and values["cable.area"] is not None:
        values["cable.inertia"] = default_inertia(values["cable.area"])
    if values["model.kind"] == "longitudinal":
        values["load.type"] = given.get("load.type", LONGITUDINAL_LOAD)
        if not any(mentioned(d) for d in END_TIME_KEYS):
            values["solver.transits"] = DEFAULT_TRANSITS
        return values
    if not mentioned("solver.t_end"):
        values["solver.t_end"] = DEFAULT_T_END
    paper = values["model.coefficients"] == "paper"
    if paper and not (mentioned("initial.displacement") or mentioned("initial.velocity")):
        values["initial.velocity"] = PAPER_VELOCITY
    return values


def _check_times(values: dict[str, Any]) -> None:
    """Transverse: intervals and steps must fit inside the simulated time."""
    t_end = values["solver.t_end"]
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
    _check_sample_count(values, "outputs.time_series")


def _check_sample_count(values: dict[str, Any], wanted: str) -> None:
    """Refuse a sample interval that gives more than MAX_SAMPLES samples per point, when the
    samples are asked for (``wanted``) and solver.t_end is known."""
    t_end, interval = values["solver.t_end"], values["outputs.sample_interval"]
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
    if has_base(values, axes) and any(
            _extreme(values, axes, d, np.max) > 0.0 for d in BASE_LEVEL_KEYS
            if values[d] is not None or schema.BY_DOTTED[d].axis in axes):
        return
    for dotted in ("initial.displacement", "initial.velocity"):
        if (_extreme(values, axes, dotted, np.min) != 0.0
                or _extreme(values, axes, dotted, np.max) != 0.0):
            return
    what = ""
    if not given and not axes:
        what = (f"the scene sets no keys, so it runs one point of the defaults (a "
                f"{values['cable.length']:g} m span, {values['load.amplitude']:g} N "
                f"{values['load.type']} end load, {values['solver.t_end']:g} s): ")
    warnings.warn(f"{what}initial.displacement = initial.velocity = 0 at every point, and the "
                  "end load only changes the stiffness, so every point stays at q = 0 "
                  "(state decayed, amplitude 0); give a start, e.g. initial.displacement = "
                  "1e-4 (m)", CableSweepWarning, stacklevel=4)


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
    same-signed ones), so its largest and smallest magnitudes lie at corners."""
    kind = values["model.kind"]
    corners = list(itertools.product(*([float(a[0]), float(a[-1])] for a in axes.values())))
    columns = dict(zip(axes, np.array(corners, dtype=np.float64).T)) if axes else {}
    params: dict[str, Any] = {name: columns.get(name, _float64(values[key.dotted]))
                              for name, key in schema.BY_AXIS.items()}
    if params["inertia"] is None:
        params["inertia"] = default_inertia(params["area"])
    params.update(coefficients=values["model.coefficients"], load_type=values["load.type"],
                  paper_parametric=values["model.paper_parametric"],
                  divergence_bound=values["metrics.divergence_bound"])
    if params["load_type"] == "constant":
        params["frequency"] = None
    with np.errstate(all="ignore"):
        if kind == "longitudinal":
            from ..models.wave import wave_parameters
            derived = wave_parameters(params, values["solver.t_end"], values["solver.transits"])
        else:
            from ..models.modal import oscillator
            derived = oscillator(params)
    bad = [(name, np.atleast_1d(np.asarray(derived[name], dtype=np.float64)))
           for name in _CHECKED_COEFFICIENTS[kind]]
    bad = [(name, v) for name, v in bad if not np.all(np.isfinite(v))]
    if not bad:
        return
    name, coefficient = bad[0]
    corner = int(np.argmax(~np.isfinite(coefficient))) if coefficient.size > 1 else 0
    inputs = []
    for axis, key in schema.BY_AXIS.items():
        value = params[axis]
        if value is None or key.section not in ("cable", "model", "load", "base"):
            continue
        value = float(np.atleast_1d(value)[corner % np.size(value)])
        where = (f"axis '{axis}' at {value!r}" if axis in axes
                 else f"scene key '{key.dotted}' = {value!r}")
        inputs.append((not (value == 0 or _PLAUSIBLE[0] <= abs(value) <= _PLAUSIBLE[1]), where))
    named = [w for odd, w in inputs if odd] or [w for _, w in inputs]
    _fail(", ".join(named),
          f"give the derived coefficient {name} = {float(coefficient[corner])!r}, not a "
          f"finite float64 (so are: {', '.join(n for n, _ in bad)})",
          "give the cable data in SI units with physical magnitudes, e.g. cable.density = "
          "8900 kg/m^3, cable.area = 6e-6 m^2, cable.youngs_modulus = 1.1e11 Pa")


# --------------------------------------------------------------------------- messages


def _fail(where: str, problem: str, fix: str) -> NoReturn:
    """Raise a one-line SceneError: ``WHERE: PROBLEM (FIX)``."""
    message = f"{where}: {problem} ({fix})"
    raise SceneError(message.replace("\r", "\\r").replace("\n", "\\n"))


def _close(word: str, candidates: Any) -> str | None:
    """The closest candidate to a misspelt word, or None."""
    matches = difflib.get_close_matches(word, list(candidates), n=1)
    return matches[0] if matches else None


def _suggestion(guess: str | None, fallback: str) -> str:
    return f"did you mean '{guess}'?" if guess else fallback


def _show(value: Any) -> str:
    """A short repr of a user's value for a message."""
    try:
        text = repr(value)
    except (ValueError, RecursionError):         # an int of > 4300 digits, deep nesting
        text = f"<a {type(value).__name__} too large to show>"
    return text if len(text) <= 60 else text[:57] + "..."


def _comment_text(text: str) -> str:
    """Text safe inside a TOML comment (no control characters)."""
    return "".join(c if c.isprintable() else "?" for c in repr(text))


# --------------------------------------------------------------------------- TOML writer


def _toml_value(value: Any) -> str:
    """TOML for a str, bool, int, float, or list of numbers."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        return _toml_array(value)
    raise TypeError(f"cannot write {type(value).__name__} as a TOML value")


def _toml_array(values: Any, per_line: int = 8) -> str:
    """A TOML array of numbers, wrapped every ``per_line`` items."""
    items = [_toml_value(v) for v in (values.tolist() if isinstance(values, np.ndarray) else values)]
    if len(items) <= per_line:
        return "[" + ", ".join(items) + "]"
    rows = [", ".join(items[i:i + per_line]) for i in range(0, len(items), per_line)]
    return "[\n    " + ",\n    ".join(rows) + ",\n]"


def _toml_string(text: str) -> str:
    """A TOML basic string with the escapes TOML requires."""
    escapes = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n",
               "\f": "\\f", "\r": "\\r"}
    out = []
    for char in text:
        if char in escapes:
            out.append(escapes[char])
        elif ord(char) < 0x20 or ord(char) == 0x7F:
            out.append(f"\\u{ord(char):04X}")
        else:
            out.append(char)
    return '"' + "".join(out) + '"'


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.fullmatch(key) else _toml_string(key)
