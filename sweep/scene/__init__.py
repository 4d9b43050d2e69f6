"""Scene files: load a sweep description from TOML, validate it, and write it back.

A scene is a TOML document (see docs/architecture.md) checked against the table in `sweep.schema`.
`load_scene` takes a built-in name (a file in ``sweep/scenes/``) or a path, applies
``KEY=VALUE`` overrides to the parsed document, validates everything, and returns a
`Scene`: every scalar key resolved (defaults applied) plus one float64 array per axis.

Every mistake a user can make raises `SceneError` with a one-line message of the form
``WHERE: what is wrong (how to fix it)``, where WHERE names the dotted key, axis or file.

Resolution rules worth knowing:
- A key swept under ``[axes]`` has ``values[key] = None``; its values live in ``axes``.
  If the key is also given as a scalar, the axis wins.
- An override that sets a sweepable key as a scalar removes that key's axis, an override
  of one key of an either-or pair (the load frequency, the base level, the base frequency)
  removes the other, and an override of one end-time key (``solver.t_end``,
  ``solver.transits``) removes the other, so ``--set`` can always replace what the scene file
  says.
- The rules that are physics (which keys and axes each ``model.kind`` takes, its defaults,
  the Courant limit, the paper cable, base excitation, time levels, coefficients finite at
  the grid's corners, the zero-solution warning) are the models': sweep/models/rules.py.

The package, one job a module (each re-exported name below keeps working from here):
    build      the pipeline: load_scene, load_scene_text (read, override, check, resolve)
    reading    finding and reading a built-in scene or a file; size, encoding, TOML syntax
    overrides  --set KEY=VALUE: parsed, applied, either-or partners dropped
    units      values with units ("33.3 g/m", "0.5 g") converted to SI first (pint, lazily)
    values     the document's keys and each value against the schema (kind, bounds, choices)
    axes       [axes]: lists and {start, stop, num, spacing} ranges, exact
    document   the Scene and its TOML writer
    messages   the one-line SceneError (_fail), suggestions, quoted values
"""

from __future__ import annotations

from typing import Any

# Every name below is imported from its module on first use (PEP 562): `sweep scenes` reads the
# built-in scenes without NumPy. name -> the module that defines it.
_NAMES: dict[str, str] = {
    **{name: "sweep.models.rules" for name in (
        "BASE_FIX", "BASE_FREQUENCY_KEYS", "BASE_KEYS", "BASE_LEVEL_KEYS",
        "DEFAULT_FREQUENCY_RATIO", "DEFAULT_T_END", "DEFAULT_TRANSITS", "END_TIME_KEYS",
        "FREQUENCY_KEYS", "LEVEL_LIMIT", "LONGITUDINAL_AXES", "LONGITUDINAL_LOAD", "MAX_SAMPLES",
        "PAIRS", "PAPER_CABLE", "PAPER_FIXED_AXES", "PAPER_VELOCITY", "default_inertia",
        "has_base")},
    **{name: "sweep.scene.axes" for name in (
        "LOG_DIGITS", "MAX_AXIS_POINTS", "RANGE_KEYS", "linear_range", "log_range")},
    "load_scene": "sweep.scene.build", "load_scene_text": "sweep.scene.build",
    "Scene": "sweep.scene.document", "parse_override": "sweep.scene.overrides",
    "MAX_SCENE_BYTES": "sweep.scene.reading", "_scenes_dir": "sweep.scene.reading",
    "builtin_scenes": "sweep.scene.reading", "MAX_INT": "sweep.scene.values",
}

__all__ = ["Scene", "builtin_scenes", "has_base", "linear_range", "load_scene",
           "load_scene_text", "log_range", "parse_override"]


def __getattr__(name: str) -> Any:
    if name in _NAMES:
        import importlib
        value = getattr(importlib.import_module(_NAMES[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_NAMES))
